//! `taut preview FILE.gcode|TRACE.vcd --machine … -o out.png|svg`: a
//! toolpath as a picture, the pen down solid and its travel dashed.
//!
//! G-code is read through the firmware's parser and interpreter
//! (`toolpath::from_gcode`); a simulator trace (`cargo xtask sim --vcd`)
//! through the pulse replay: a plotter's steps and pen pulses, or — with
//! `--machine string_art --card DIR` — the nails the string-art job wrapped,
//! drawn as `taut stringart`'s preview draws the card's pattern.

use crate::args::Args;
use crate::raster::{Canvas, Rgb};
use crate::stringart::picture;
use crate::svg::{num, points, Svg};
use crate::toolpath::{self, Toolpath};
use std::path::{Path, PathBuf};
use taut_logic::config::MachineConfig;
use taut_logic::machine::Machine;
use taut_trace::replay::{board_from_param, JobReplay};
use taut_trace::vcd;

pub const USAGE: &str = "\
taut preview FILE.gcode|TRACE.vcd --machine flatbed|drum|whiteboard|scara|string_art -o out.png|svg
    [--px 1000] [--card DIR --thread-mm 0.3 (string_art traces)]";

const INK: Rgb = [20, 20, 40];
const TRAVEL: Rgb = [70, 130, 230];

/// The view: the toolpath's extent with a 5 % margin, mm, y up.
fn view(path: &Toolpath) -> ([f64; 2], f64) {
    let (lo, hi) = path.bounds();
    if path.moves.is_empty() {
        return ([-1.0, -1.0], 2.0);
    }
    let span = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1.0) * 1.1;
    let centre = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0];
    ([centre[0] - span / 2.0, centre[1] - span / 2.0], span)
}

/// The toolpath on a `px`² picture.
pub fn png(path: &Toolpath, px: usize) -> Canvas {
    let (corner, span) = view(path);
    let scale = px as f64 / span;
    let at = |p: [f64; 2]| {
        [
            ((p[0] - corner[0]) * scale) as f32,
            (px as f64 - (p[1] - corner[1]) * scale) as f32,
        ]
    };
    let mut c = Canvas::new(px, px, [255; 3]);
    for m in path.moves.iter().filter(|m| !m.down) {
        c.dashed(at(m.from), at(m.to), 1.0, TRAVEL, 4.0);
    }
    for m in path.moves.iter().filter(|m| m.down) {
        c.line(at(m.from), at(m.to), 1.6, INK, 1.0);
    }
    c
}

/// The toolpath in mm, 1:1: the pen's strokes solid, travel dashed.
pub fn svg(path: &Toolpath) -> String {
    let (corner, span) = view(path);
    let mut s = Svg::new(corner[0], -(corner[1] + span), span, span);
    let flip = |p: [f64; 2]| [p[0], -p[1]];
    // Consecutive moves of one kind as one polyline.
    let mut runs: Vec<(bool, Vec<[f64; 2]>)> = Vec::new();
    for m in &path.moves {
        match runs.last_mut() {
            Some((down, pts)) if *down == m.down && pts.last() == Some(&flip(m.from)) => {
                pts.push(flip(m.to))
            }
            _ => runs.push((m.down, vec![flip(m.from), flip(m.to)])),
        }
    }
    let width = num(span / 500.0);
    for (down, pts) in runs {
        let style = match down {
            true => format!("stroke=\"#141428\" stroke-width=\"{width}\""),
            false => format!(
                "stroke=\"#4682e6\" stroke-width=\"{width}\" stroke-dasharray=\"{} {}\"",
                num(span / 150.0),
                num(span / 150.0)
            ),
        };
        s.push(&format!(
            "<polyline points=\"{}\" fill=\"none\" {style}/>",
            points(pts)
        ));
    }
    s.finish()
}

/// Writes the toolpath as PNG or SVG, by `out`'s extension.
pub fn save(path: &Toolpath, out: &Path, px: usize) -> Result<(), String> {
    match extension(out)?.as_str() {
        "svg" => std::fs::write(out, svg(path)).map_err(|e| format!("{}: {e}", out.display())),
        _ => png(path, px).save_png(out),
    }
}

fn extension(out: &Path) -> Result<String, String> {
    let ext = out
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "png" | "svg" => Ok(ext),
        _ => Err(format!(
            "{}: the picture must be .png or .svg",
            out.display()
        )),
    }
}

/// The nails the string-art job wrapped, from its trace.
pub fn wrapped_nails(
    signals: &[vcd::Signal],
    param_txt: &[u8],
) -> Result<(taut_logic::geometry::Board, Vec<u16>), String> {
    let board = board_from_param(param_txt)?;
    let job = JobReplay::from_signals(signals, board, &MachineConfig::STRING_ART)?;
    Ok((board, job.wrapped_nails()))
}

/// `taut preview …` from the command line.
pub fn run(mut args: Args) -> Result<(), String> {
    let input = PathBuf::from(args.positional("FILE.gcode or TRACE.vcd")?);
    let name = args.required("machine")?;
    let machine =
        Machine::parse(name.as_bytes()).ok_or(format!("--machine {name}: not a machine"))?;
    let out = PathBuf::from(args.required("o")?);
    let px = args.number("px", 1000usize)?;
    let card = args.value("card").map(PathBuf::from);
    let thread_mm = args.number("thread-mm", 0.3)?;
    args.finish()?;
    extension(&out)?;
    let text = std::fs::read_to_string(&input).map_err(|e| format!("{}: {e}", input.display()))?;
    let is_vcd = input
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("vcd"));
    if machine == Machine::StringArt {
        if !is_vcd {
            return Err("a string-art job is previewed from its trace (.vcd) with --card".into());
        }
        let card = card.ok_or("--card DIR: the job's card (its param.txt) is needed")?;
        let param = card.join("param.txt");
        let param = std::fs::read(&param).map_err(|e| format!("{}: {e}", param.display()))?;
        let signals = vcd::parse(&text)?;
        let (board, nails) = wrapped_nails(&signals, &param)?;
        match extension(&out)?.as_str() {
            "svg" => std::fs::write(&out, picture::svg(&board, &nails, thread_mm))
                .map_err(|e| e.to_string())?,
            _ => picture::png(&board, &nails, thread_mm, px).save_png(&out)?,
        }
        println!(
            "{}: {} nails wrapped; written {}",
            input.display(),
            nails.len(),
            out.display()
        );
        return Ok(());
    }
    let path = match is_vcd {
        true => toolpath::from_vcd(&vcd::parse(&text)?, machine)?,
        false => {
            toolpath::from_gcode(&text, machine).map_err(|e| format!("{}: {e}", input.display()))?
        }
    };
    save(&path, &out, px)?;
    let (down, up) = path.lengths();
    println!(
        "{}: pen down {down:.0} mm, up {up:.0} mm; written {}",
        input.display(),
        out.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::toolpath::Move;

    fn square() -> Toolpath {
        let m = |from, to, down| Move { from, to, down };
        Toolpath {
            moves: vec![
                m([0.0, 0.0], [10.0, 10.0], false),
                m([10.0, 10.0], [30.0, 10.0], true),
                m([30.0, 10.0], [30.0, 30.0], true),
                m([30.0, 30.0], [0.0, 0.0], false),
            ],
        }
    }

    #[test]
    fn pen_down_is_solid_and_travel_dashed() {
        let c = png(&square(), 330);
        // 33 mm over 330 px, from −1.5 mm: x = 20 mm is pixel 215, y = 10
        // mm row 330 − 115 = 215.
        let at = |x: usize, y: usize| &c.rgb[(y * 330 + x) * 3..][..3];
        assert!(at(215, 215)[0] < 100, "{:?}", at(215, 215));
        // The diagonal travel: some of it drawn, some of it gap.
        let travel: Vec<bool> = (40..300)
            .map(|k| at(k, 330 - k)[2] > 200 && at(k, 330 - k)[0] < 200)
            .collect();
        assert!(travel.iter().any(|&b| b) && travel.iter().any(|&b| !b));
        let doc = svg(&square());
        assert_eq!(doc.matches("<polyline").count(), 3);
        assert!(doc.contains("points=\"10,-10 30,-10 30,-30\""), "{doc}");
        assert!(doc.contains("stroke-dasharray"));
    }

    #[test]
    fn only_png_or_svg() {
        assert!(save(&square(), Path::new("/tmp/x.jpg"), 10)
            .unwrap_err()
            .ends_with("must be .png or .svg"));
    }
}
