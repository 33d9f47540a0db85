//! `taut vectorize IMAGE --machine flatbed|drum|whiteboard|scara
//! --width-mm W -o out.gcode`: a picture to plotter G-code, seed 002's
//! pipeline without OpenCV.
//!
//! Grey levels → edges (Canny, `--canny LOW,HIGH`) followed pixel by pixel
//! into chains, or (`--mode hatch`) the outlines of the regions darker than
//! `--threshold` and parallel hatching inside them → point reduction within
//! `--tolerance-mm` → the strokes ordered for less pen-up travel (before
//! and after printed) → G-code in the machine's dialect, read back through
//! the firmware's interpreter → `out.gcode` and a preview PNG beside it.

pub mod canny;
pub mod hatch;
pub mod order;
pub mod simplify;
pub mod trace;

use crate::args::Args;
use crate::gray::Gray;
use crate::toolpath::Toolpath;
use crate::{plot, preview, progress};
use std::path::PathBuf;
use taut_logic::machine::Machine;
use trace::Polyline;

pub const USAGE: &str = "\
taut vectorize IMAGE --machine flatbed|drum|whiteboard|scara --width-mm W -o out.gcode
    [--mode edges|hatch] [--canny 50,150] [--blur 1.4] [--threshold 0.5] [--hatch-mm 1]
    [--angle 45] [--tolerance-mm 0.1] [--min-length-mm 0.5] [--at X,Y] [--feed 1500]
    [--preview out.png]";

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mode {
    /// Canny edges, thresholds on the 0–255 gradient (OpenCV's scale).
    Edges { low: f32, high: f32 },
    /// Outlines and hatching of the regions darker than `threshold` (0–1).
    Hatch {
        threshold: f32,
        spacing_mm: f64,
        angle: f64,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    pub machine: Machine,
    pub width_mm: f64,
    pub mode: Mode,
    /// Gaussian smoothing before edges or threshold, pixels.
    pub blur: f32,
    pub tolerance_mm: f64,
    pub min_length_mm: f64,
    /// The drawing's lower left corner, mm.
    pub at: Option<[f64; 2]>,
    pub feed: f64,
}

impl Options {
    pub fn new(machine: Machine, width_mm: f64) -> Options {
        Options {
            machine,
            width_mm,
            mode: Mode::Edges {
                low: 50.0,
                high: 150.0,
            },
            blur: 1.4,
            tolerance_mm: 0.1,
            min_length_mm: 0.5,
            at: None,
            feed: 1500.0,
        }
    }
}

/// What came out, with the pen-up travel of the strokes in the order they
/// were traced and in the order drawn.
pub struct Vectorized {
    pub strokes: Vec<Polyline>,
    pub gcode: String,
    pub toolpath: Toolpath,
    pub pen_up_traced_mm: f64,
    pub pen_up_ordered_mm: f64,
}

/// Longest side the picture is worked at, pixels (larger ones are scaled
/// down first).
const MAX_SIDE: usize = 2000;

pub fn vectorize(image: &Gray, o: &Options, title: &str) -> Result<Vectorized, String> {
    if o.width_mm.is_nan() || o.width_mm <= 0.0 {
        return Err("--width-mm must be above 0".into());
    }
    let image = match image.width.max(image.height) > MAX_SIDE {
        true => {
            let k = MAX_SIDE as f64 / image.width.max(image.height) as f64;
            let size = |v: usize| ((v as f64 * k).round() as usize).max(1);
            image.resized(size(image.width), size(image.height))
        }
        false => image.clone(),
    };
    let (w, h) = (image.width, image.height);
    let mm_per_px = o.width_mm / w as f64;
    let size = [o.width_mm, h as f64 * mm_per_px];
    let at =
        o.at.unwrap_or_else(|| plot::default_corner(o.machine, size));
    let spin = progress::spinner("tracing");
    let traced: Vec<Polyline> = match o.mode {
        Mode::Edges { low, high } => {
            if !(low >= 0.0 && high >= low) {
                return Err("--canny LOW,HIGH: 0 ≤ LOW ≤ HIGH".into());
            }
            let edge = canny::edges(&image, o.blur, low, high);
            trace::chains(&edge, w, h)
        }
        Mode::Hatch {
            threshold,
            spacing_mm,
            angle,
        } => {
            if spacing_mm.is_nan() || spacing_mm <= 0.0 {
                return Err("--hatch-mm must be above 0".into());
            }
            let smooth = match o.blur > 0.0 {
                true => canny::gaussian(&image.pixels, w, h, o.blur),
                false => image.pixels.clone(),
            };
            let dark: Vec<bool> = smooth.iter().map(|&v| v < threshold).collect();
            let mut lines = trace::outlines(&dark, w, h);
            lines.extend(hatch::hatch(&dark, w, h, spacing_mm / mm_per_px, angle));
            lines
        }
    };
    // Pixels (y down) to the G-code's millimetres (y up).
    let to_mm = |p: &[f64; 2]| {
        [
            at[0] + p[0] * mm_per_px,
            at[1] + (h as f64 - p[1]) * mm_per_px,
        ]
    };
    let strokes: Vec<Polyline> = traced
        .iter()
        .map(|line| simplify::simplify(&line.iter().map(to_mm).collect::<Vec<_>>(), o.tolerance_mm))
        .filter(|s| s.len() >= 2 && length(s) >= o.min_length_mm)
        .collect();
    spin.finish_and_clear();
    if strokes.is_empty() {
        return Err(match o.mode {
            Mode::Edges { .. } => "no edges found: lower the --canny thresholds".into(),
            Mode::Hatch { .. } => "nothing darker than --threshold: raise it".into(),
        });
    }
    let spin = progress::spinner("ordering");
    let home = [0.0, 0.0];
    let pen_up_traced_mm = order::pen_up_mm(&strokes, home);
    let strokes = order::order(strokes, home);
    let pen_up_ordered_mm = order::pen_up_mm(&strokes, home);
    spin.finish_and_clear();
    let (gcode, toolpath) = plot::plot(&strokes, o.machine, o.feed, title)?;
    Ok(Vectorized {
        strokes,
        gcode,
        toolpath,
        pen_up_traced_mm,
        pen_up_ordered_mm,
    })
}

fn length(s: &[[f64; 2]]) -> f64 {
    s.windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
        .sum()
}

/// `taut vectorize …` from the command line.
pub fn run(mut args: Args) -> Result<(), String> {
    let image_path = PathBuf::from(args.positional("IMAGE")?);
    let machine = plot::machine(&args.required("machine")?)?;
    let mut o = Options::new(machine, args.number("width-mm", f64::NAN)?);
    let [low, high] = args.pair("canny")?.unwrap_or([50.0, 150.0]);
    let threshold = args.number("threshold", 0.5f32)?;
    let spacing_mm = args.number("hatch-mm", 1.0)?;
    let angle = args.number("angle", 45.0)?;
    o.mode = match args.value("mode").as_deref() {
        None | Some("edges") => Mode::Edges {
            low: low as f32,
            high: high as f32,
        },
        Some("hatch") => Mode::Hatch {
            threshold,
            spacing_mm,
            angle,
        },
        Some(m) => return Err(format!("--mode {m}: edges or hatch")),
    };
    o.blur = args.number("blur", o.blur)?;
    o.tolerance_mm = args.number("tolerance-mm", o.tolerance_mm)?;
    o.min_length_mm = args.number("min-length-mm", o.min_length_mm)?;
    o.at = args.pair("at")?;
    o.feed = args.number("feed", o.feed)?;
    let out = PathBuf::from(args.required("o")?);
    let preview_path = args
        .value("preview")
        .map(PathBuf::from)
        .unwrap_or_else(|| out.with_extension("png"));
    args.finish()?;

    let image = Gray::open(&image_path)?;
    let title = format!("taut vectorize {}", image_path.display());
    let v = vectorize(&image, &o, &title)?;
    std::fs::write(&out, &v.gcode).map_err(|e| format!("{}: {e}", out.display()))?;
    preview::save(&v.toolpath, &preview_path, 1000)?;
    let (down, up) = v.toolpath.lengths();
    let (lo, hi) = v.toolpath.bounds();
    println!(
        "{}: {} strokes, {} G-code lines for the {}",
        image_path.display(),
        v.strokes.len(),
        v.gcode.lines().count(),
        machine.name()
    );
    println!(
        "  drawing X {:.1}…{:.1}, Y {:.1}…{:.1} mm; pen down {:.0} mm, up {:.0} mm",
        lo[0], hi[0], lo[1], hi[1], down, up
    );
    println!(
        "  pen-up travel: {:.0} mm in traced order, {:.0} mm ordered ({:.0} % less)",
        v.pen_up_traced_mm,
        v.pen_up_ordered_mm,
        100.0 * (1.0 - v.pen_up_ordered_mm / v.pen_up_traced_mm.max(1e-9))
    );
    println!("  written: {}, {}", out.display(), preview_path.display());
    Ok(())
}

#[cfg(test)]
mod tests;
