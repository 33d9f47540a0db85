//! `taut preview FILE.gcode|DRAWING.svg|TRACE.vcd --machine … -o
//! out.png|svg`: a toolpath as a picture, the pen down solid and its travel
//! dashed.
//!
//! G-code is read through the firmware's parser and interpreter
//! (`toolpath::from_gcode`); an SVG drawing as `taut vectorize` would draw
//! it with its defaults (its own size, its layers in order); a simulator trace (`cargo xtask sim --vcd`)
//! through the pulse replay: a plotter's steps and pen pulses, or — with
//! `--machine string_art --card DIR` — the nails the string-art job wrapped,
//! drawn as `taut stringart`'s preview draws the card's pattern.

use crate::cli::AnyMachine;
use crate::raster::{Canvas, Rgb};
use crate::stringart::picture;
use crate::svg::{num, points, Svg};
use crate::toolpath::{self, Toolpath};
use std::path::{Path, PathBuf};
use taut_logic::config::MachineConfig;
use taut_logic::machine::Machine;
use taut_trace::replay::{board_from_param, JobReplay};
use taut_trace::vcd;

/// A toolpath (G-code or a simulator trace) as a picture
#[derive(clap::Args, Debug)]
#[command(after_help = "\
Examples:
  taut preview horse.gcode --machine flatbed -o horse.png
  taut preview drawing.svg --machine flatbed -o drawing.png
  cargo xtask sim --vcd run.vcd …; taut preview run.vcd --machine flatbed -o run.svg
  taut preview job.vcd --machine string_art --card CARD -o wound.png")]
pub struct Cli {
    /// The G-code file, an SVG drawing (drawn as `taut vectorize` draws it
    /// with its defaults), or a simulator trace (.vcd)
    pub input: PathBuf,
    /// The machine the file is for
    #[arg(long, value_enum)]
    pub machine: AnyMachine,
    /// The picture (.png or .svg)
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Side of the PNG, pixels
    #[arg(long, default_value_t = 1000)]
    pub px: usize,
    /// The string-art job's card (its param.txt), for a string_art trace
    #[arg(long, value_name = "DIR")]
    pub card: Option<PathBuf>,
    /// The thread's width in a string_art picture, mm
    #[arg(long, default_value_t = 0.3)]
    pub thread_mm: f64,
}

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

/// The toolpath as PNG or SVG bytes, by `out`'s extension.
pub fn bytes(path: &Toolpath, out: &Path, px: usize) -> Result<Vec<u8>, String> {
    Ok(match extension(out)?.as_str() {
        "svg" => svg(path).into_bytes(),
        _ => png(path, px).png(),
    })
}

/// Writes the toolpath as PNG or SVG, by `out`'s extension, atomically.
pub fn save(path: &Toolpath, out: &Path, px: usize) -> Result<(), String> {
    crate::output::write(out, &bytes(path, out, px)?)
}

/// `png` or `svg`, from the picture's name; anything else is refused.
pub fn extension(out: &Path) -> Result<String, String> {
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
pub fn run(cli: Cli) -> Result<(), String> {
    let (input, out, px, card, thread_mm) =
        (cli.input, cli.output, cli.px, cli.card, cli.thread_mm);
    let machine = Machine::from(cli.machine);
    let param_path = card.as_ref().map(|c| c.join("param.txt"));
    let mut inputs = vec![input.as_path()];
    inputs.extend(param_path.as_deref());
    crate::output::refuse_overwriting(&inputs, &[&out])?;
    extension(&out)?;
    let bytes = std::fs::read(&input).map_err(|e| format!("{}: {e}", input.display()))?;
    if machine != Machine::StringArt && crate::vectorize::is_svg(&bytes) {
        return svg_drawing(&input, machine, &out, px);
    }
    let text = String::from_utf8(bytes).map_err(|_| {
        format!(
            "{}: neither G-code, SVG nor a trace (not UTF-8 text)",
            input.display()
        )
    })?;
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
        let picture = match extension(&out)?.as_str() {
            "svg" => picture::svg(&board, &nails, thread_mm).into_bytes(),
            _ => picture::png(&board, &nails, thread_mm, px).png(),
        };
        crate::output::write(&out, &picture)?;
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

/// An SVG drawing as `taut vectorize` draws it with its defaults.
fn svg_drawing(input: &Path, machine: Machine, out: &Path, px: usize) -> Result<(), String> {
    use crate::vectorize::{self, Options, Source};
    let source = Source::open(input)?;
    let mut o = Options::new(machine, 1.0);
    o.width_mm = None;
    let v = vectorize::vectorize(&source, &o, &input.display().to_string())?;
    for w in &v.warnings {
        eprintln!("warning: {w}");
    }
    save(&v.toolpath, out, px)?;
    let (down, up) = v.toolpath.lengths();
    println!(
        "{}: {} strokes in {} pass(es), pen down {down:.0} mm, up {up:.0} mm; written {}",
        input.display(),
        v.strokes.len(),
        v.layers.len(),
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
