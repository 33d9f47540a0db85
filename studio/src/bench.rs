//! `taut bench [--json FILE]`: the string-art figures of docs/benchmarks.md, on
//! the host — for each example image, a 250-nail circle (R 40.2 cm, the
//! spec's board), 3000 lines of 0.3 mm thread at 512 px: our generator,
//! the plain greedy and random chords, side by side. With `--json` the
//! figures are added to that file (`cargo xtask bench` passes
//! `target/bench.json`): `stringart_rmse_<image>` and
//! `stringart_seconds_<image>` for ours, `…_plain_<image>` for the plain
//! greedy, `stringart_rmse_random_<image>`, `stringart_thread_m_<image>`.

use crate::args::Args;
use crate::gray::Gray;
use crate::progress;
use crate::stringart::card::{thread_mm, Spec};
use crate::stringart::{generate, Method, Options};
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};

pub const USAGE: &str = "taut bench [--json target/bench.json] [--images DIR]";

pub const IMAGES: [&str; 3] = ["camera.jpg", "astronaut.jpg", "horse.png"];

/// The figures' board and winding.
pub fn options() -> Options {
    Options::new(
        Spec {
            shape: 0,
            nails: 250,
            radius_um: 402_000,
        },
        3000,
    )
}

pub fn run(mut args: Args) -> Result<(), String> {
    let json_path = args.value("json").map(PathBuf::from);
    let dir = args
        .value("images")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/images"));
    args.finish()?;
    let o = options();
    let board = o.spec.board()?;
    let mut figures = Map::new();
    println!(
        "string art: 250-nail circle, R 40.2 cm, 3000 lines of {} mm thread, {} px; RMSE of darkness, blurred σ 2 px",
        o.thread_mm, o.resolution
    );
    println!(
        "{:<14} {:>22} {:>22} {:>8}",
        "image", "ours: RMSE / s / m", "plain: RMSE / s / m", "random"
    );
    for name in IMAGES {
        let image = Gray::open(&dir.join(name))?;
        let key = name.split('.').next().unwrap_or(name);
        let mut row = Vec::new();
        for method in [Method::Ours, Method::Plain, Method::Random] {
            let bar = progress::bar(key, 0);
            let w = generate(
                &image,
                &Options {
                    method,
                    ..o.clone()
                },
                &bar,
            )?;
            bar.finish_and_clear();
            row.push((w.rmse, w.seconds, thread_mm(&board, &w.pattern) / 1000.0));
        }
        let [ours, plain, random] = [row[0], row[1], row[2]];
        println!(
            "{name:<14} {:>8.4} / {:>4.1} / {:>4.0} {:>8.4} / {:>4.1} / {:>4.0} {:>8.4}",
            ours.0, ours.1, ours.2, plain.0, plain.1, plain.2, random.0
        );
        let r = |v: f64, d: i32| (v * 10f64.powi(d)).round() / 10f64.powi(d);
        figures.insert(format!("stringart_rmse_{key}"), json!(r(ours.0, 4)));
        figures.insert(format!("stringart_seconds_{key}"), json!(r(ours.1, 2)));
        figures.insert(format!("stringart_thread_m_{key}"), json!(r(ours.2, 1)));
        figures.insert(format!("stringart_rmse_plain_{key}"), json!(r(plain.0, 4)));
        figures.insert(
            format!("stringart_seconds_plain_{key}"),
            json!(r(plain.1, 2)),
        );
        figures.insert(
            format!("stringart_thread_m_plain_{key}"),
            json!(r(plain.2, 1)),
        );
        figures.insert(
            format!("stringart_rmse_random_{key}"),
            json!(r(random.0, 4)),
        );
    }
    if let Some(path) = json_path {
        merge(&path, figures)?;
        println!("added to {}", path.display());
    }
    Ok(())
}

/// Adds `figures` to the JSON object in `path` (made if missing).
fn merge(path: &Path, figures: Map<String, Value>) -> Result<(), String> {
    let fail = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    let mut all = match std::fs::read_to_string(path) {
        Ok(text) => match serde_json::from_str(&text).map_err(|e| fail(&e))? {
            Value::Object(m) => m,
            _ => return Err(fail(&"not a JSON object")),
        },
        Err(_) => Map::new(),
    };
    all.extend(figures);
    let text = serde_json::to_string_pretty(&Value::Object(all)).map_err(|e| fail(&e))?;
    std::fs::write(path, text).map_err(|e| fail(&e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_join_the_benchs_json() {
        let path = std::env::temp_dir().join(format!("taut-bench-{}.json", std::process::id()));
        std::fs::write(&path, "{\"flash_bytes\": 5}").unwrap();
        let mut m = Map::new();
        m.insert("stringart_rmse_camera".into(), json!(0.1));
        merge(&path, m).unwrap();
        let v: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        assert_eq!(v["flash_bytes"], 5);
        assert_eq!(v["stringart_rmse_camera"], 0.1);
        std::fs::remove_file(&path).unwrap();
    }
}
