//! `taut vectorize INPUT --machine … -o out.gcode`: a picture or an SVG
//! file to plotter G-code, with a preview and the machine time.
//!
//! - SVG ([`svgfile`]): every shape in millimetres; curves cut into
//!   chords within half a step of the machine; fills hatched; layers (or
//!   colours) become passes with a pen change between them.
//! - Pictures (PNG, JPEG): line art → centre-lines ([`skeleton`]); shapes
//!   and photographs → outlines ([`contour`], sub-pixel) and hatching at
//!   several tone levels ([`fill`]); or Canny edges ([`canny`]). The
//!   threshold comes from the histogram (Otsu, [`tone`]) unless given.
//!
//! Then: placed on the paper ([`place`]), strokes simplified within the
//! tolerance, touching strokes merged and all ordered for less pen-up
//! travel ([`order`]), G-code in the machine's dialect, read back through
//! the firmware's interpreter, timed by its planner.

pub mod canny;
pub mod contour;
pub mod fill;
pub mod order;
pub mod place;
pub mod simplify;
pub mod skeleton;
pub mod svgfile;
pub mod tone;
pub mod trace;

use crate::args::{pair, positive, Plotter};
use crate::gray::Gray;
use crate::plot::Layer;
use crate::toolpath::Toolpath;
use crate::{plot, progress};
use place::{Layout, Place};
use std::path::{Path, PathBuf};
use taut_logic::machine::Machine;
use trace::Polyline;

const EXAMPLES: &str = "\
Examples:
  taut vectorize drawing.svg --machine flatbed -o drawing.gcode
  taut vectorize logo.svg --machine drum --paper A4 --fit --margin-mm 15 -o logo.gcode
  taut vectorize horse.png --machine flatbed --width-mm 100 -o horse.gcode
  taut vectorize sketch.png --machine whiteboard --paper A3 --landscape --fit --mode centerline -o sketch.gcode
  taut vectorize portrait.jpg --machine drum --width-mm 150 --mode hatch --levels 5 --cross -o portrait.gcode

An SVG is drawn at its own size (its page's lower left corner at the machine's
origin) unless --width-mm or --fit scales it; a picture needs --width-mm or --fit.
The preview goes to OUT's name with .preview.png (horse.gcode: horse.preview.png)
unless --preview names it; no output may be an input.";

/// A picture (PNG, JPEG) or an SVG drawing to plotter G-code, with a preview
#[derive(clap::Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct Cli {
    /// The picture (PNG, JPEG) or drawing (SVG)
    pub input: PathBuf,
    /// The machine the G-code is for
    #[arg(long, value_enum)]
    pub machine: Plotter,
    /// The G-code file
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// The preview picture (.png or .svg) [default: OUT.preview.png]
    #[arg(long)]
    pub preview: Option<PathBuf>,
    /// The drawing's width, mm [default: an SVG's own]
    #[arg(long, value_parser = positive)]
    pub width_mm: Option<f64>,
    /// The paper: A5, A4, A3, A2, letter, legal, tabloid or WxH (mm); the drawing is centred on it
    #[arg(long, value_parser = place::paper)]
    pub paper: Option<[f64; 2]>,
    /// The paper lies landscape (its long side along X)
    #[arg(long, requires = "paper")]
    pub landscape: bool,
    /// Scale the drawing to fill the paper within the margins
    #[arg(long, requires = "paper")]
    pub fit: bool,
    /// Room --fit leaves at each edge of the paper, mm
    #[arg(long, default_value_t = 10.0)]
    pub margin_mm: f64,
    /// The drawing's lower left corner X,Y, mm [default: centred on the paper; else the origin, the whiteboard centred]
    #[arg(long, value_parser = pair, allow_hyphen_values = true)]
    pub at: Option<[f64; 2]>,
    /// Turn the drawing, degrees counter-clockwise
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub rotate: f64,
    /// Pictures: centre-lines for line art, hatching for shapes and tones (auto picks by the picture)
    #[arg(long, value_enum, default_value_t = Mode::Auto)]
    pub mode: Mode,
    /// Grey level (0 black … 1 white) below which a pixel is ink [default: from the histogram, Otsu]
    #[arg(long)]
    pub threshold: Option<f32>,
    /// Tone levels of hatching (each darker level adds lines)
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u8).range(1..=16))]
    pub levels: u8,
    /// Cross-hatch: every other tone level at right angles
    #[arg(long)]
    pub cross: bool,
    /// Spacing of the densest hatching (pictures) and of fills (SVG), mm
    #[arg(long, value_parser = positive, default_value_t = 0.8)]
    pub hatch_mm: f64,
    /// Hatching's angle on the paper, degrees
    #[arg(long, default_value_t = 45.0, allow_hyphen_values = true)]
    pub angle: f64,
    /// Canny's thresholds LOW,HIGH on the 0–255 gradient (--mode edges)
    #[arg(long, value_parser = pair, default_value = "50,150")]
    pub canny: [f64; 2],
    /// Gaussian smoothing of a picture, pixels
    #[arg(long, default_value_t = 1.0)]
    pub blur: f32,
    /// Most a simplified stroke may leave the traced one, mm [default: half a step of the machine; pictures: at least a quarter pixel]
    #[arg(long, value_parser = positive)]
    pub tolerance_mm: Option<f64>,
    /// Strokes shorter than this are dropped, mm [default: pictures 0.5, SVG 0]
    #[arg(long)]
    pub min_length_mm: Option<f64>,
    /// Draw every layer in one pass, without stopping for a pen change
    #[arg(long)]
    pub one_pen: bool,
    /// Drawing feed, mm/min
    #[arg(long, default_value_t = 1500.0)]
    pub feed: f64,
}

/// How a picture becomes strokes.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Centre-lines for line art, hatching (with outlines) otherwise
    Auto,
    /// The outlines of the dark regions, at sub-pixel precision
    Outline,
    /// One stroke along the middle of each dark line
    Centerline,
    /// Tone levels hatched, two-toned shapes outlined too
    Hatch,
    /// Canny's edges, traced
    Edges,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    pub machine: Machine,
    /// The drawing's width, mm (an SVG: its own when `None`).
    pub width_mm: Option<f64>,
    pub layout: Layout,
    pub mode: Mode,
    pub threshold: Option<f32>,
    pub levels: usize,
    pub cross: bool,
    pub hatch_mm: f64,
    pub angle: f64,
    pub canny: [f32; 2],
    /// Gaussian smoothing before tracing, pixels.
    pub blur: f32,
    pub tolerance_mm: Option<f64>,
    pub min_length_mm: Option<f64>,
    pub one_pen: bool,
    pub feed: f64,
}

impl Options {
    pub fn new(machine: Machine, width_mm: f64) -> Options {
        Options {
            machine,
            width_mm: Some(width_mm),
            layout: Layout {
                margin: 10.0,
                ..Layout::default()
            },
            mode: Mode::Auto,
            threshold: None,
            levels: 4,
            cross: false,
            hatch_mm: 0.8,
            angle: 45.0,
            canny: [50.0, 150.0],
            blur: 1.0,
            tolerance_mm: None,
            min_length_mm: None,
            one_pen: false,
            feed: 1500.0,
        }
    }
}

/// What is drawn from.
pub enum Source {
    Picture(Gray),
    Svg(svgfile::Document),
}

impl Source {
    /// A PNG, JPEG or SVG file, told apart by its bytes.
    pub fn open(path: &Path) -> Result<Source, String> {
        let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let source = match crate::svg::is_svg(&bytes) {
            true => svgfile::read(&bytes).map(Source::Svg),
            false => Gray::decode(&bytes)
                .map(Source::Picture)
                .map_err(|e| format!("{e} (nor SVG)")),
        };
        source.map_err(|e| format!("{}: {e}", path.display()))
    }
}

/// What came out.
pub struct Vectorized {
    /// The passes, their strokes in drawing order.
    pub layers: Vec<Layer>,
    /// Every stroke in drawing order.
    pub strokes: Vec<Polyline>,
    pub gcode: String,
    pub toolpath: Toolpath,
    /// Pen-up travel in the order traced and in the order drawn, mm.
    pub pen_up_traced_mm: f64,
    pub pen_up_ordered_mm: f64,
    /// The machine time by the firmware's planner, s.
    pub seconds: f64,
    /// The mode a picture was traced in, and its ink threshold.
    pub mode: Option<(Mode, f32)>,
    pub place: Place,
    pub warnings: Vec<String>,
}

/// Longest side a picture is worked at, pixels (larger ones are scaled
/// down first).
const MAX_SIDE: usize = 2000;

pub fn vectorize(source: &Source, o: &Options, title: &str) -> Result<Vectorized, String> {
    if let Some(w) = o.width_mm {
        if w.is_nan() || w <= 0.0 {
            return Err("--width-mm must be above 0".into());
        }
    }
    let mut warnings = Vec::new();
    let (layers, place, mode) = match source {
        Source::Picture(g) => {
            let (layer, place, mode) = picture(g, o, &mut warnings)?;
            (vec![layer], place, Some(mode))
        }
        Source::Svg(d) => {
            let (layers, place) = drawing(d, o, &mut warnings)?;
            (layers, place, None)
        }
    };
    let all: Vec<Polyline> = layers
        .iter()
        .flat_map(|l| l.strokes.iter().cloned())
        .collect();
    let (lo, hi) = bounds(&all);
    place::check_travel(lo, hi, o.machine)?;
    let spin = progress::spinner("ordering");
    let merge_mm = 2.0 * plot::half_step_mm(o.machine, centre(lo, hi));
    let home = [0.0, 0.0];
    let pen_up_traced_mm = order::pen_up_mm(&all, home);
    let mut at = home;
    let mut ordered = Vec::new();
    for layer in layers {
        let strokes = order::order(order::merge(layer.strokes, merge_mm), at);
        at = strokes.last().and_then(|s| s.last()).copied().unwrap_or(at);
        ordered.push(Layer {
            name: layer.name,
            strokes,
        });
    }
    let flat: Vec<Polyline> = ordered
        .iter()
        .flat_map(|l| l.strokes.iter().cloned())
        .collect();
    let pen_up_ordered_mm = order::pen_up_mm(&flat, home);
    spin.finish_and_clear();
    let passes: Vec<Layer> = match o.one_pen {
        true => vec![Layer {
            name: String::new(),
            strokes: ordered.into_iter().flat_map(|l| l.strokes).collect(),
        }],
        false => ordered,
    };
    let (gcode, toolpath) = plot::plot_layers(&passes, o.machine, o.feed, title)?;
    let seconds = plot::seconds(&gcode, o.machine);
    Ok(Vectorized {
        strokes: passes
            .iter()
            .flat_map(|l| l.strokes.iter().cloned())
            .collect(),
        layers: passes,
        gcode,
        toolpath,
        pen_up_traced_mm,
        pen_up_ordered_mm,
        seconds,
        mode,
        place,
        warnings,
    })
}

fn centre(lo: [f64; 2], hi: [f64; 2]) -> [f64; 2] {
    [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0]
}

/// Least and greatest x and y of all points.
pub fn bounds(strokes: &[Polyline]) -> ([f64; 2], [f64; 2]) {
    strokes
        .iter()
        .flatten()
        .fold(([f64::MAX; 2], [f64::MIN; 2]), |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1])],
                [hi[0].max(p[0]), hi[1].max(p[1])],
            )
        })
}

fn layout_of(o: &Options) -> Layout {
    o.layout.clone()
}

/// The simplified strokes that are long enough.
fn finish(strokes: Vec<Polyline>, tolerance: f64, min_length: f64) -> Vec<Polyline> {
    strokes
        .into_iter()
        .map(|s| simplify::simplify(&s, tolerance))
        .filter(|s| s.len() >= 2 && length(s) >= min_length.max(1e-9))
        .collect()
}

/// A picture's strokes, placed.
fn picture(
    image: &Gray,
    o: &Options,
    warnings: &mut Vec<String>,
) -> Result<(Layer, Place, (Mode, f32)), String> {
    let image = match image.width.max(image.height) > MAX_SIDE {
        true => {
            let k = MAX_SIDE as f64 / image.width.max(image.height) as f64;
            let size = |v: usize| ((v as f64 * k).round() as usize).max(1);
            image.resized(size(image.width), size(image.height))
        }
        false => image.clone(),
    };
    let (w, h) = (image.width, image.height);
    // The picture's frame: a pixel is `unit` mm before placing.
    let unit = match (o.width_mm, o.layout.fit) {
        (Some(width), _) => width / w as f64,
        (None, true) => 1.0,
        (None, false) => {
            return Err("give the drawing's size: --width-mm W, or --paper … --fit".into())
        }
    };
    let place = place::place(
        [0.0, 0.0],
        [w as f64 * unit, h as f64 * unit],
        &layout_of(o),
        o.machine,
    )?;
    let px_mm = unit * place.scale;
    let to_mm = |p: &[f64; 2]| place.apply([p[0] * unit, (h as f64 - p[1]) * unit]);
    let middle = place.apply([w as f64 * unit / 2.0, h as f64 * unit / 2.0]);
    let tolerance = o
        .tolerance_mm
        .unwrap_or_else(|| plot::half_step_mm(o.machine, middle).max(0.25 * px_mm));
    let min_length = o.min_length_mm.unwrap_or(0.5);
    let spin = progress::spinner("tracing");
    let smooth = match o.blur > 0.0 {
        true => canny::gaussian(&image.pixels, w, h, o.blur),
        false => image.pixels.clone(),
    };
    let (otsu, separation) = tone::otsu(&smooth);
    let threshold = o.threshold.unwrap_or(otsu);
    let mode = match o.mode {
        Mode::Auto => match tone::kind(&smooth, w, h, threshold) {
            tone::Kind::LineArt => Mode::Centerline,
            _ => Mode::Hatch,
        },
        m => m,
    };
    let mut used = threshold;
    let strokes: Vec<Polyline> = match mode {
        Mode::Edges | Mode::Outline | Mode::Centerline => {
            let pixels = match mode {
                Mode::Edges => {
                    let [low, high] = o.canny;
                    if !(low >= 0.0 && high >= low) {
                        return Err("--canny LOW,HIGH: 0 ≤ LOW ≤ HIGH".into());
                    }
                    let edge = canny::edges(&image, o.blur, low, high);
                    trace::chains(&edge, w, h)
                }
                Mode::Outline => contour::iso(&smooth, w, h, threshold),
                _ => {
                    let dark: Vec<bool> = smooth.iter().map(|&v| v < threshold).collect();
                    skeleton::centre_lines(&dark, w, h)
                }
            };
            finish(
                pixels
                    .iter()
                    .map(|l| l.iter().map(to_mm).collect())
                    .collect(),
                tolerance,
                min_length,
            )
        }
        Mode::Hatch | Mode::Auto => {
            // Tones over the picture's whole range; a two-toned picture's
            // (Otsu's separation ≥ 0.9) levels lie below its ink threshold,
            // and it is outlined.
            let two_toned = separation >= 0.9;
            let stretched = tone::stretch(&smooth);
            let lightest = match (o.threshold, two_toned) {
                (Some(t), _) => t,
                (None, true) => tone::otsu(&stretched).0,
                (None, false) => o.levels as f32 / (o.levels as f32 + 1.0),
            };
            used = lightest;
            let mut lines = Vec::new();
            if two_toned {
                let rings = contour::iso(&stretched, w, h, lightest);
                lines.extend(
                    rings
                        .iter()
                        .map(|l| l.iter().map(to_mm).collect::<Polyline>()),
                );
            }
            lines.extend(hatch_tones(&stretched, w, h, &to_mm, lightest, o));
            if warnings.is_empty() && tone::vanished(&stretched, lightest) > 0.5 {
                warnings.push(vanished_warning(
                    tone::vanished(&stretched, lightest),
                    lightest,
                ));
            }
            finish(lines, tolerance, min_length)
        }
    };
    spin.finish_and_clear();
    if matches!(mode, Mode::Outline | Mode::Centerline) {
        let lost = tone::vanished(&smooth, threshold);
        if lost > 0.5 {
            warnings.push(vanished_warning(lost, threshold));
        }
    }
    if strokes.is_empty() {
        return Err(match mode {
            Mode::Edges => "no edges found: lower the --canny thresholds".into(),
            _ => format!("nothing darker than the threshold {used:.2}: raise --threshold"),
        });
    }
    Ok((
        Layer {
            name: String::new(),
            strokes,
        },
        place,
        (mode, used),
    ))
}

fn vanished_warning(share: f64, threshold: f32) -> String {
    format!(
        "{:.0} % of the picture's visible grey is lighter than the threshold {threshold:.2} and is not drawn: \
         raise --threshold, or --mode hatch for tones",
        100.0 * share
    )
}

/// Hatching at the tone levels: a pixel darker than k levels lies under k
/// sets of lines. The lines of one direction are `hatch_mm` apart where
/// all its levels overlap, each level's set offset by its share of that.
fn hatch_tones(
    pixels: &[f32],
    w: usize,
    h: usize,
    to_mm: &dyn Fn(&[f64; 2]) -> [f64; 2],
    lightest: f32,
    o: &Options,
) -> Vec<Polyline> {
    let levels = tone::levels(lightest, o.levels);
    let directions = if o.cross { 2 } else { 1 };
    let mut out = Vec::new();
    for (k, &level) in levels.iter().enumerate() {
        let d = k % directions;
        // Levels of this direction, and this one's place among them.
        let count = (d..levels.len()).step_by(directions).count();
        let j = k / directions;
        let rings: Vec<Polyline> = contour::iso(pixels, w, h, level)
            .iter()
            .map(|r| r.iter().map(to_mm).collect())
            .collect();
        let angle = o.angle + 90.0 * d as f64;
        let phase = (j as f64 + 0.5) / count as f64;
        out.extend(fill::hatch(
            &rings,
            fill::Rule::EvenOdd,
            o.hatch_mm * count as f64,
            angle,
            phase,
        ));
    }
    out
}

/// An SVG drawing's layers, placed.
fn drawing(
    d: &svgfile::Document,
    o: &Options,
    warnings: &mut Vec<String>,
) -> Result<(Vec<Layer>, Place), String> {
    if d.texts > 0 {
        warnings.push(format!(
            "{} text element(s) not drawn: convert text to paths first (Inkscape: Path → Object to Path)",
            d.texts
        ));
    }
    if d.images > 0 {
        warnings.push(format!(
            "{} embedded picture(s) not drawn: vectorize the picture on its own",
            d.images
        ));
    }
    let outlines: Vec<&svgfile::Outline> = d
        .layers
        .iter()
        .flat_map(|l| &l.shapes)
        .flat_map(|s| &s.outlines)
        .collect();
    if outlines.is_empty() {
        return Err("nothing to draw: the SVG has no visible shapes".into());
    }
    // With --fit the ink's box is fitted; else the page is placed.
    let unit = o.width_mm.map_or(1.0, |w| w / d.size[0]);
    let (lo, hi) = match o.layout.fit {
        true => bounds(&[outlines.iter().flat_map(|ol| ol.hull()).collect()]),
        false => ([0.0, 0.0], d.size),
    };
    let (lo, hi) = ([lo[0] * unit, lo[1] * unit], [hi[0] * unit, hi[1] * unit]);
    let place = place::place(lo, hi, &layout_of(o), o.machine)?;
    let map = |p: [f64; 2]| place.apply([p[0] * unit, p[1] * unit]);
    let middle = place.apply(centre(lo, hi));
    let tolerance = o
        .tolerance_mm
        .unwrap_or_else(|| plot::half_step_mm(o.machine, middle));
    let min_length = o.min_length_mm.unwrap_or(0.0);
    let mut layers = Vec::new();
    for layer in &d.layers {
        let mut strokes = Vec::new();
        for shape in &layer.shapes {
            let placed: Vec<Polyline> = shape
                .outlines
                .iter()
                .map(|ol| ol.map(map).flatten(tolerance))
                .collect();
            if let Some(rule) = shape.fill {
                strokes.extend(fill::hatch(&placed, rule, o.hatch_mm, o.angle, 0.5));
            }
            strokes.extend(placed);
        }
        // Flattened already within the tolerance: only exact repeats go.
        let strokes: Vec<Polyline> = strokes
            .into_iter()
            .map(|s| simplify::simplify(&s, 0.0))
            .filter(|s| s.len() >= 2 && length(s) > min_length.max(1e-9))
            .collect();
        if !strokes.is_empty() {
            layers.push(Layer {
                name: layer.name.clone(),
                strokes,
            });
        }
    }
    if layers.is_empty() {
        return Err(
            "nothing to draw: the SVG's shapes are all shorter than --min-length-mm".into(),
        );
    }
    Ok((layers, place))
}

fn length(s: &[[f64; 2]]) -> f64 {
    s.windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
        .sum()
}

/// The options of the command line.
pub fn options(cli: &Cli) -> Options {
    let mut o = Options::new(Machine::from(cli.machine), 1.0);
    o.width_mm = cli.width_mm;
    o.layout = Layout {
        paper: cli.paper.map(|p| match cli.landscape {
            true => [p[0].max(p[1]), p[0].min(p[1])],
            false => p,
        }),
        margin: cli.margin_mm,
        fit: cli.fit,
        at: cli.at,
        rotate: cli.rotate,
    };
    o.mode = cli.mode;
    o.threshold = cli.threshold;
    o.levels = usize::from(cli.levels);
    o.cross = cli.cross;
    o.hatch_mm = cli.hatch_mm;
    o.angle = cli.angle;
    o.canny = [cli.canny[0] as f32, cli.canny[1] as f32];
    o.blur = cli.blur;
    o.tolerance_mm = cli.tolerance_mm;
    o.min_length_mm = cli.min_length_mm;
    o.one_pen = cli.one_pen;
    o.feed = cli.feed;
    o
}

/// `taut vectorize …` from the command line.
pub fn run(cli: Cli) -> Result<(), String> {
    let o = options(&cli);
    let (input, out) = (cli.input, cli.output);
    let preview_path = cli
        .preview
        .unwrap_or_else(|| crate::output::derived(&out, "preview", "png"));
    crate::output::refuse_overwriting(&[&input], &[&out, &preview_path])?;
    crate::output::picture_extension(&preview_path)?;

    let source = Source::open(&input)?;
    let title = format!(
        "taut vectorize {}",
        input
            .file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned())
    );
    let v = vectorize(&source, &o, &title)?;
    let mut files = crate::output::Batch::new();
    files.add(&out, v.gcode.as_bytes());
    files.add(
        &preview_path,
        crate::render::bytes(&v.toolpath, &preview_path, 1000)?,
    );
    files.commit()?;
    for w in &v.warnings {
        eprintln!("warning: {w}");
    }
    report(&input, &v, o.machine);
    println!("  written: {}, {}", out.display(), preview_path.display());
    Ok(())
}

fn report(input: &Path, v: &Vectorized, machine: Machine) {
    let (down, up) = v.toolpath.lengths();
    let (lo, hi) = bounds(&v.strokes);
    let how = match v.mode {
        Some((m, t)) => format!(" ({} at threshold {t:.2})", format!("{m:?}").to_lowercase()),
        None => String::new(),
    };
    println!(
        "{}: {} strokes{how}, {} G-code lines for the {}",
        input.display(),
        v.strokes.len(),
        v.gcode.lines().count(),
        machine.name()
    );
    if v.layers.len() > 1 {
        let names: Vec<String> = v.layers.iter().map(|l| format!("{:?}", l.name)).collect();
        println!(
            "  {} passes, a pen change (M0) before each after the first: {}",
            v.layers.len(),
            names.join(", ")
        );
    }
    if (v.place.scale - 1.0).abs() > 1e-9 {
        println!("  scaled × {:.3} to fit", v.place.scale);
    }
    println!(
        "  drawing X {:.1}…{:.1}, Y {:.1}…{:.1} mm; pen down {down:.0} mm, pen up {up:.0} mm",
        lo[0], hi[0], lo[1], hi[1]
    );
    println!(
        "  pen-up travel: {:.0} mm in traced order, {:.0} mm merged and ordered ({:.0} % less)",
        v.pen_up_traced_mm,
        v.pen_up_ordered_mm,
        100.0 * (1.0 - v.pen_up_ordered_mm / v.pen_up_traced_mm.max(1e-9))
    );
    println!(
        "  drawing time {} by the firmware's planner (default settings{})",
        crate::stringart::hours(v.seconds),
        if v.layers.len() > 1 {
            ", pen changes not counted"
        } else {
            ""
        }
    );
}

#[cfg(test)]
mod tests;
