//! The `taut` binary as a maker meets it: every subcommand explains
//! itself, a misspelt flag is refused with a suggestion, no run writes over
//! its input (or any file it reads), and a run killed at any moment leaves
//! each output whole — old or new, never half.

use clap::CommandFactory;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;
use taut_studio::cli::Cli;

fn taut(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_taut"))
        .args(args)
        .output()
        .unwrap()
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("taut-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples")
        .join(name)
}

#[test]
fn every_subcommand_has_help_listing_its_flags() {
    let cli = Cli::command();
    let mut seen = 0;
    for sub in cli.get_subcommands() {
        let name = sub.get_name();
        let out = taut(&[name, "--help"]);
        assert!(out.status.success(), "taut {name} --help: {}", text(&out));
        let help = text(&out);
        for arg in sub.get_arguments() {
            if let Some(long) = arg.get_long() {
                assert!(
                    help.contains(&format!("--{long}")),
                    "taut {name} --help lacks --{long}:\n{help}"
                );
            }
        }
        // Defaults are shown; the commands that make files give examples.
        if sub
            .get_arguments()
            .any(|a| !a.get_default_values().is_empty())
        {
            assert!(
                help.contains("[default: "),
                "taut {name} --help shows no default"
            );
        }
        if [
            "stringart",
            "template",
            "vectorize",
            "text",
            "preview",
            "send",
            "studio",
        ]
        .contains(&name)
        {
            assert!(
                help.contains("Example"),
                "taut {name} --help has no example"
            );
        }
        seen += 1;
    }
    assert!(seen >= 8, "{seen} subcommands");
    let top = taut(&["--help"]);
    assert!(top.status.success() && text(&top).contains("vectorize"));
    let bash = taut(&["completions", "bash"]);
    assert!(
        bash.status.success()
            && text(&bash).contains("vectorize")
            && text(&bash).contains("--width-mm")
    );
}

#[test]
fn misspelt_and_missing_flags_are_named() {
    let out = taut(&["vectorize", "x.svg", "--machin", "flatbed", "-o", "x.gcode"]);
    assert_eq!(out.status.code(), Some(2));
    let e = text(&out);
    assert!(
        e.contains("unexpected argument '--machin'")
            && e.contains("tip: a similar argument exists: '--machine'"),
        "{e}"
    );
    let out = taut(&["studio", "--serail", "/dev/ttyACM0"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out).contains("tip: a similar argument exists: '--serial'"),
        "{}",
        text(&out)
    );
    let out = taut(&[
        "template", "--nails", "100", "--shape", "circle", "-o", "t.svg",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out).contains("required arguments were not provided")
            && text(&out).contains("--radius-cm")
    );
    let out = taut(&[
        "vectorize",
        "x.svg",
        "--machine",
        "plotter",
        "-o",
        "x.gcode",
    ]);
    assert!(
        text(&out).contains("possible values: flatbed, drum, whiteboard, scara"),
        "{}",
        text(&out)
    );
}

/// Runs `args` in `dir` and checks the files named `inputs` are the same
/// bytes after it.
fn unchanged(dir: &Path, inputs: &[&str], args: &[&str]) -> Output {
    let before: Vec<Vec<u8>> = inputs
        .iter()
        .map(|f| std::fs::read(dir.join(f)).unwrap())
        .collect();
    let out = Command::new(env!("CARGO_BIN_EXE_taut"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    for (f, b) in inputs.iter().zip(before) {
        assert_eq!(
            std::fs::read(dir.join(f)).unwrap(),
            b,
            "{f} changed by taut {args:?}"
        );
    }
    out
}

#[test]
fn no_run_writes_over_its_input() {
    let d = scratch("inputs");
    std::fs::copy(example("images/horse.png"), d.join("horse.png")).unwrap();
    std::fs::copy(example("svg/shapes.svg"), d.join("shapes.svg")).unwrap();
    let ok = |o: &Output| assert!(o.status.success(), "{}", text(o));
    // Outputs next to the input, named after it: the preview is
    // horse.preview.png, not horse.png.
    let o = unchanged(
        &d,
        &["horse.png"],
        &[
            "vectorize",
            "horse.png",
            "--machine",
            "flatbed",
            "--width-mm",
            "40",
            "-o",
            "horse.gcode",
        ],
    );
    ok(&o);
    assert!(d.join("horse.preview.png").exists() && d.join("horse.gcode").exists());
    ok(&unchanged(
        &d,
        &["shapes.svg"],
        &[
            "vectorize",
            "shapes.svg",
            "--machine",
            "flatbed",
            "-o",
            "shapes.gcode",
        ],
    ));
    ok(&unchanged(
        &d,
        &["horse.gcode"],
        &[
            "preview",
            "horse.gcode",
            "--machine",
            "flatbed",
            "-o",
            "horse-path.png",
        ],
    ));
    ok(&unchanged(
        &d,
        &["horse.png"],
        &[
            "stringart",
            "horse.png",
            "--nails",
            "24",
            "--shape",
            "circle",
            "--radius-cm",
            "10",
            "--lines",
            "20",
            "--resolution",
            "64",
            "--zoom",
            "2",
            "--offset",
            "-0.1,0.05",
            "--invert",
            "--mask",
            "horse.png",
            "-o",
            ".",
        ],
    ));
    assert!(d.join("target.png").exists() && d.join("poradi.txt").exists());
    ok(&unchanged(
        &d,
        &["horse.png", "shapes.svg"],
        &["text", "Hi", "--height-mm", "5", "-o", "hi.gcode"],
    ));
    ok(&unchanged(
        &d,
        &["horse.png"],
        &[
            "template",
            "--nails",
            "24",
            "--shape",
            "circle",
            "--radius-cm",
            "10",
            "-o",
            "template.svg",
        ],
    ));
    // An output that is an input, by any name, is refused before anything
    // is written.
    std::fs::create_dir_all(d.join("sub")).unwrap();
    let refused = [
        vec![
            "vectorize",
            "horse.png",
            "--machine",
            "flatbed",
            "--width-mm",
            "40",
            "-o",
            "sub/../horse.png",
        ],
        vec![
            "vectorize",
            "horse.png",
            "--machine",
            "flatbed",
            "--width-mm",
            "40",
            "-o",
            "x.gcode",
            "--preview",
            "horse.png",
        ],
        vec![
            "vectorize",
            "shapes.svg",
            "--machine",
            "flatbed",
            "-o",
            "y.gcode",
            "--preview",
            "./shapes.svg",
        ],
        vec![
            "preview",
            "horse.gcode",
            "--machine",
            "flatbed",
            "-o",
            "horse.gcode",
        ],
        vec![
            "stringart",
            "preview.png",
            "--nails",
            "24",
            "--shape",
            "circle",
            "--radius-cm",
            "10",
            "--lines",
            "20",
            "-o",
            ".",
        ],
        vec!["bench", "--json", "horse.png", "--images", "."],
    ];
    for args in refused {
        let names = ["horse.png", "horse.gcode", "preview.png", "shapes.svg"];
        let o = unchanged(&d, &names, &args);
        assert!(!o.status.success(), "taut {args:?} ran");
        assert!(
            text(&o).contains("is an input of this run"),
            "taut {args:?}: {}",
            text(&o)
        );
    }
    assert!(!d.join("x.gcode").exists() && !d.join("y.gcode").exists());
    // `send` reads its file and writes nothing.
    let o = unchanged(
        &d,
        &["horse.gcode"],
        &["send", "horse.gcode", "--port", "/nonexistent/tty"],
    );
    assert!(!o.status.success());
    std::fs::remove_dir_all(&d).unwrap();
}

/// Every file under `d` (one folder deep), by its path relative to `d`.
fn files(d: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(d).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            for f in std::fs::read_dir(&p).unwrap() {
                out.push(f.unwrap().path().strip_prefix(d).unwrap().to_path_buf());
            }
        } else {
            out.push(p.strip_prefix(d).unwrap().to_path_buf());
        }
    }
    out.sort();
    out
}

/// `taut ARGS` in `d` killed at `n` seeded moments through its run (and a
/// little past it): each of its outputs is then either the older file or
/// the one a whole run writes, and what a kill leaves besides is a hidden
/// temporary file. Returns (outputs, kills that left the old files, kills
/// that left the new ones).
fn killed_runs(d: &Path, args: &[&str], n: usize, seed: u64) -> (usize, usize, usize) {
    // The whole run once: what a finished run writes, and how long it takes.
    let before = files(d);
    let start = Instant::now();
    let o = Command::new(env!("CARGO_BIN_EXE_taut"))
        .args(args)
        .current_dir(d)
        .output()
        .unwrap();
    assert!(o.status.success(), "taut {args:?}: {}", text(&o));
    let took = start.elapsed();
    let outputs: Vec<PathBuf> = files(d)
        .into_iter()
        .filter(|f| !before.contains(f))
        .collect();
    assert!(!outputs.is_empty(), "taut {args:?} wrote nothing");
    let new: Vec<Vec<u8>> = outputs
        .iter()
        .map(|f| std::fs::read(d.join(f)).unwrap())
        .collect();
    let old: Vec<Vec<u8>> = outputs
        .iter()
        .map(|f| format!("an older {}", f.display()).into_bytes())
        .collect();
    let mut seed = seed;
    let mut kinds = [0usize; 2];
    for _ in 0..n {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let at = took.mul_f64((seed >> 33) as f64 / (1u64 << 31) as f64 * 1.1);
        for (f, b) in outputs.iter().zip(&old) {
            std::fs::write(d.join(f), b).unwrap();
        }
        let mut child = Command::new(env!("CARGO_BIN_EXE_taut"))
            .args(args)
            .current_dir(d)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(at);
        let _ = child.kill();
        child.wait().unwrap();
        let mut all_new = true;
        for ((f, o), w) in outputs.iter().zip(&old).zip(&new) {
            let now = std::fs::read(d.join(f)).unwrap();
            assert!(
                now == *o || now == *w,
                "taut {args:?}: {} is neither the old file nor the new one ({} bytes) after a kill at {at:?}",
                f.display(),
                now.len()
            );
            all_new &= now == *w;
        }
        kinds[usize::from(all_new)] += 1;
        for f in files(d) {
            if !before.contains(&f) && !outputs.contains(&f) {
                let name = f.file_name().unwrap().to_string_lossy().into_owned();
                assert!(
                    name.starts_with('.') && name.ends_with(".tmp"),
                    "taut {args:?} left {}",
                    f.display()
                );
                std::fs::remove_file(d.join(&f)).unwrap();
            }
        }
    }
    eprintln!(
        "taut {}: {} outputs, {n} runs of {took:?} killed: {} left old files (some or all), {} all new ones",
        args[0],
        outputs.len(),
        kinds[0],
        kinds[1]
    );
    (outputs.len(), kinds[0], kinds[1])
}

#[test]
fn a_run_killed_at_a_random_moment_leaves_whole_files() {
    let d = scratch("killed");
    std::fs::copy(example("images/horse.png"), d.join("horse.png")).unwrap();
    let runs: [&[&str]; 4] = [
        &[
            "vectorize",
            "horse.png",
            "--machine",
            "drum",
            "--width-mm",
            "120",
            "--mode",
            "hatch",
            "-o",
            "out.gcode",
        ],
        &[
            "stringart",
            "horse.png",
            "--nails",
            "120",
            "--shape",
            "circle",
            "--radius-cm",
            "20",
            "--lines",
            "600",
            "--resolution",
            "200",
            "-o",
            "card",
        ],
        &[
            "template",
            "--nails",
            "250",
            "--shape",
            "circle",
            "--radius-cm",
            "40.2",
            "--paper",
            "A4",
            "-o",
            "template.svg",
        ],
        &[
            "text",
            "Příliš žluťoučký kůň úpěl ďábelské ódy",
            "--height-mm",
            "8",
            "--wrap-mm",
            "100",
            "-o",
            "text.gcode",
        ],
    ];
    for (k, args) in runs.iter().enumerate() {
        let (outputs, _, _) = killed_runs(&d, args, 8, 0x5eed_0029 + k as u64);
        assert!(outputs >= 2, "taut {}: {outputs} outputs", args[0]);
    }
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn errors_name_the_file_and_exit_1() {
    let o = taut(&[
        "vectorize",
        "/nonexistent/x.svg",
        "--machine",
        "flatbed",
        "-o",
        &std::env::temp_dir()
            .join("taut-never.gcode")
            .display()
            .to_string(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(text(&o).contains("/nonexistent/x.svg"), "{}", text(&o));
}

#[test]
fn an_svg_previews_as_vectorize_draws_it() {
    let d = scratch("svg-preview");
    let svg = example("svg/inkscape-layers.svg");
    let svg = svg.to_str().unwrap();
    let v = taut(&[
        "vectorize",
        svg,
        "--machine",
        "flatbed",
        "-o",
        d.join("layers.gcode").to_str().unwrap(),
    ]);
    assert!(v.status.success(), "{}", text(&v));
    let p = taut(&[
        "preview",
        svg,
        "--machine",
        "flatbed",
        "-o",
        d.join("layers.png").to_str().unwrap(),
    ]);
    assert!(p.status.success(), "{}", text(&p));
    assert!(text(&p).contains("in 3 pass(es)"), "{}", text(&p));
    let read = |f: &str| std::fs::read(d.join(f)).unwrap();
    assert_eq!(
        read("layers.png"),
        read("layers.preview.png"),
        "the SVG's preview is the drawing vectorize makes of it"
    );
    // And the G-code vectorize wrote previews the same again.
    let g = taut(&[
        "preview",
        d.join("layers.gcode").to_str().unwrap(),
        "--machine",
        "flatbed",
        "-o",
        d.join("layers-gcode.png").to_str().unwrap(),
    ]);
    assert!(g.status.success(), "{}", text(&g));
    assert_eq!(read("layers-gcode.png"), read("layers.png"));
    let _ = std::fs::remove_dir_all(&d);
}
