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

use crate::args::AnyMachine;
use crate::output::picture_extension;
use crate::render::save;
use crate::stringart::picture;
use crate::toolpath;
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
    picture_extension(&out)?;
    let bytes = std::fs::read(&input).map_err(|e| format!("{}: {e}", input.display()))?;
    if machine != Machine::StringArt && crate::svg::is_svg(&bytes) {
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
        let picture = match picture_extension(&out)?.as_str() {
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
    use crate::render::{png, svg};
    use crate::toolpath::{Move, Toolpath};

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
