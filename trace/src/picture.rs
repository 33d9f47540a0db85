//! A picture of the string-art job as the pulses made it: a PNG rebuilt
//! from the VCD signals alone (through [`crate::replay`]), to be looked at.
//!
//! ```no_run
//! # fn main() -> std::io::Result<()> {
//! use taut_trace::{picture, replay, vcd};
//! use taut_logic::config::MachineConfig;
//! let text = std::fs::read_to_string("trace.vcd")?;
//! let signals = vcd::parse(&text).map_err(std::io::Error::other)?;
//! let board = replay::board_from_param(&std::fs::read("card/param.txt")?)
//!     .map_err(std::io::Error::other)?;
//! let summary = picture::render_job(
//!     &signals,
//!     board,
//!     &MachineConfig::STRING_ART,
//!     std::path::Path::new("job.png"),
//! )?;
//! println!("{} holes, {} wraps", summary.holes, summary.wraps);
//! # Ok(()) }
//! ```
//!
//! What is drawn, on a [`SIZE`]² image, the board's frame (nail 0 to the
//! right, counter-clockwise):
//! - the board (wood colour) and its outline: a circle or polygon of radius R;
//! - a small grey ring where the geometry puts each nail;
//! - a dark dot where the drill plunged, at the replayed base angle and
//!   radial position;
//! - the thread: straight dark lines from nail 0 (where it is tied) through
//!   each wrapped nail in turn, as the finished piece looks;
//! - the needle's path while winding, faint blue;
//! - in red: crossings of the ring outside a gap (a ring) and base or
//!   radial steps with the drill below the surface (a dot). A good job has
//!   no red.

mod canvas;
mod plot;

pub use canvas::Canvas;
pub use plot::{plot_points, render_plot, Plot};

use crate::replay::{JobReplay, Trace};
use crate::vcd::Signal;
use serde::Serialize;
use std::f64::consts::{PI, TAU};
use std::io;
use std::path::Path;
use taut_logic::config::MachineConfig;
use taut_logic::geometry::Board;

/// Width and height of the picture, pixels.
pub const SIZE: u32 = 900;

/// What the picture shows, counted.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Summary {
    /// Plunges of the drill below the surface.
    pub holes: usize,
    /// Wraps (outward then inward crossings of the ring) while winding.
    pub wraps: usize,
    /// The nails wrapped, in order.
    pub wrapped: Vec<u16>,
    /// Crossings of the ring while winding, and those not inside a gap.
    pub crossings: usize,
    pub crossings_outside_gaps: usize,
    /// Base or radial steps with the drill below the surface.
    pub moves_while_plunged: usize,
}

/// Replays `signals` on `board` and writes the picture to `path` (PNG).
pub fn render_job(
    signals: &[Signal],
    board: Board,
    config: &MachineConfig,
    path: &Path,
) -> io::Result<Summary> {
    let trace = Trace::from_signals(signals, config).map_err(io::Error::other)?;
    render(&JobReplay::new(trace, board, config), path)
}

/// Writes the picture of a replayed job to `path` (PNG).
pub fn render(job: &JobReplay, path: &Path) -> io::Result<Summary> {
    let (canvas, summary) = draw(job, SIZE);
    write_png(&canvas, path)?;
    Ok(summary)
}

/// `canvas` as a PNG file.
fn write_png(canvas: &Canvas, path: &Path) -> io::Result<()> {
    let file = io::BufWriter::new(std::fs::File::create(path)?);
    let mut png = png::Encoder::new(file, canvas.size, canvas.size);
    png.set_color(png::ColorType::Rgb);
    png.set_depth(png::BitDepth::Eight);
    let mut writer = png.write_header().map_err(io::Error::other)?;
    writer
        .write_image_data(&canvas.rgb)
        .map_err(io::Error::other)?;
    writer.finish().map_err(io::Error::other)
}

const WOOD: [u8; 3] = [236, 220, 188];
const OUTLINE: [u8; 3] = [120, 84, 48];
const NAIL: [u8; 3] = [130, 130, 130];
const HOLE: [u8; 3] = [40, 28, 20];
const THREAD: [u8; 3] = [20, 20, 30];
const NEEDLE: [u8; 3] = [40, 90, 200];
const FAULT: [u8; 3] = [220, 30, 30];

/// The picture in memory, with its counts.
pub fn draw(job: &JobReplay, size: u32) -> (Canvas, Summary) {
    let (from, to) = job.winding();
    // The needle's points while winding, board mm.
    let mut path = Vec::new();
    let mut pos = [
        job.trace.position(taut_logic::axis::Axis::Base, from),
        job.trace.position(taut_logic::axis::Axis::Radial, from),
    ];
    path.push(job.tool_xy(pos[0], pos[1]));
    for e in job.events() {
        if e.at_ns > from && e.at_ns <= to && e.axis < 2 {
            pos[e.axis] = e.pos;
            path.push(job.tool_xy(pos[0], pos[1]));
        }
    }
    let radius = f64::from(job.board.radius());
    let reach = path.iter().map(|p| p.0.hypot(p.1)).fold(radius, f64::max);
    let mut c = Canvas::new(size, (f64::from(size) / 2.0 - 20.0) / reach);
    let sides = board_sides(&job.board);
    c.fill_board(radius, sides, WOOD);
    let outline = outline(radius, sides);
    for w in outline.windows(2) {
        c.line(w[0], w[1], 2.0, OUTLINE, 1.0);
    }
    for i in 0..job.ring.nails() {
        c.ring(job.ring.nail_xy(i), 6.0, NAIL, 0.8);
    }
    let plunges = job.plunges();
    for p in &plunges {
        c.dot(job.tool_xy(p.base, p.radial), 4.0, HOLE, 1.0);
    }
    // The needle, thinned to half-pixel moves.
    let min = 0.5 / c.scale;
    let mut last = path[0];
    for &p in &path[1..] {
        if (p.0 - last.0).hypot(p.1 - last.1) >= min {
            c.line(last, p, 1.0, NEEDLE, 0.35);
            last = p;
        }
    }
    let wraps = job.wraps();
    let wrapped: Vec<u16> = wraps.iter().flat_map(|w| w.nails.clone()).collect();
    let mut points = vec![job.ring.nail_xy(0)];
    points.extend(wrapped.iter().map(|&n| job.ring.nail_xy(n)));
    draw_thread(&mut c, &points);
    let crossings = job.crossings();
    let bad = job.crossings_outside_gaps();
    for x in &bad {
        c.ring(job.tool_xy(x.base, x.radial), 8.0, FAULT, 1.0);
    }
    let stray = job.moves_while_plunged();
    for s in &stray {
        let t = s.at_ns;
        let (b, r) = (
            job.trace.position(taut_logic::axis::Axis::Base, t),
            job.trace.position(taut_logic::axis::Axis::Radial, t),
        );
        c.dot(job.tool_xy(b, r), 3.0, FAULT, 1.0);
    }
    let summary = Summary {
        holes: plunges.len(),
        wraps: wraps.len(),
        wrapped,
        crossings: crossings.len(),
        crossings_outside_gaps: bad.len(),
        moves_while_plunged: stray.len(),
    };
    (c, summary)
}

/// Thread as thread: 0.3 mm wide at the picture's scale, partly
/// transparent, so thousands of crossings build up the picture's tones as
/// on the board (and as in `taut`'s preview) instead of a solid black.
pub const THREAD_MM: f64 = 0.3;
const THREAD_ALPHA: f64 = 0.8;

/// The thread through `points` (board mm), in order.
fn draw_thread(c: &mut Canvas, points: &[(f64, f64)]) {
    let width = THREAD_MM * c.scale;
    for w in points.windows(2) {
        c.line(w[0], w[1], width, THREAD, THREAD_ALPHA);
    }
}

/// The number of sides of a polygonal board, `None` for a round one (told
/// by its smallest nail radius: (R − 1.5 cm)·cos(π/n)).
fn board_sides(board: &Board) -> Option<u32> {
    let scale = f64::from(board.radius()) - f64::from(taut_logic::geometry::NAIL_MARGIN_MM);
    let ratio = f64::from(board.min_nail_radius()) / scale;
    (ratio < 1.0 - 1e-4).then(|| (PI / ratio.acos()).round() as u32)
}

/// The board's edge as a closed polyline.
fn outline(radius: f64, sides: Option<u32>) -> Vec<(f64, f64)> {
    let n = sides.unwrap_or(360);
    (0..=n)
        .map(|k| {
            let a = TAU * f64::from(k) / f64::from(n);
            (radius * a.cos(), radius * a.sin())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use taut_logic::units::Milli;

    #[test]
    fn sides_and_outline_of_the_boards() {
        let hex = Board::new(6, 24, Milli(200_000)).unwrap();
        assert_eq!(board_sides(&hex), Some(6));
        assert_eq!(
            board_sides(&Board::new(3, 9, Milli(200_000)).unwrap()),
            Some(3)
        );
        assert_eq!(
            board_sides(&Board::new(0, 250, Milli(402_000)).unwrap()),
            None
        );
        let o = outline(200.0, Some(6));
        assert_eq!(o.len(), 7);
        assert!((o[1].0 - 100.0).abs() < 1e-9 && (o[6].0 - 200.0).abs() < 1e-9);
    }

    /// Thread drawn as thread: one thread leaves the wood under it a mid
    /// grey (0.3 mm of a 0.47 mm pixel, partly transparent), crossings
    /// darken further, and 300 chords over a 400 mm board on 900 pixels
    /// leave nearly all of it lighter than black (a 1.6-pixel opaque line
    /// a chord covered a third of it in black).
    #[test]
    fn threads_build_up_tones() {
        let radius = 200.0;
        let new = || {
            let mut c = Canvas::new(SIZE, (f64::from(SIZE) / 2.0 - 20.0) / radius);
            c.fill_board(radius, None, WOOD);
            c
        };
        let at = |c: &Canvas, x: u32, y: u32| c.rgb[((y * SIZE + x) * 3) as usize];
        let mut one = new();
        draw_thread(&mut one, &[(-150.0, 0.0), (150.0, 0.0)]);
        let centre = SIZE / 2;
        let on_thread = (centre - 1..=centre + 1)
            .map(|y| at(&one, centre, y))
            .min()
            .unwrap();
        assert!((60..200).contains(&on_thread), "one thread: {on_thread}");
        let mut crossed = new();
        draw_thread(
            &mut crossed,
            &[(-150.0, 0.0), (150.0, 0.0), (0.0, 150.0), (0.0, -150.0)],
        );
        let both = (centre - 1..=centre + 1)
            .map(|y| at(&crossed, centre, y))
            .min()
            .unwrap();
        assert!(
            both < on_thread,
            "a crossing is darker: {both} vs {on_thread}"
        );

        let mut c = new();
        let nail = |k: u64| {
            let a = TAU * (k % 250) as f64 / 250.0;
            (radius * 0.93 * a.cos(), radius * 0.93 * a.sin())
        };
        let mut x = 12_345u64;
        let points: Vec<(f64, f64)> = (0..300)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                nail(x)
            })
            .collect();
        draw_thread(&mut c, &points);
        let (mut dark, mut inside) = (0, 0);
        let half = f64::from(SIZE) / 2.0;
        for y in 0..SIZE {
            for xp in 0..SIZE {
                let (dx, dy) = (f64::from(xp) - half, f64::from(y) - half);
                if dx.hypot(dy) > radius * 0.9 * c.scale {
                    continue;
                }
                inside += 1;
                dark += usize::from(at(&c, xp, y) < 60);
            }
        }
        let share = dark as f64 / inside as f64;
        assert!(
            share < 0.05,
            "{:.0} % of the board near black",
            share * 100.0
        );
    }

    #[test]
    fn an_empty_trace_draws_the_bare_board() {
        let names = ["base", "radial", "drill"];
        let signals: Vec<Signal> = names
            .iter()
            .flat_map(|a| ["step", "dir", "en"].map(|p| format!("{a}_{p}")))
            .map(|name| Signal {
                name,
                initial: false,
                changes: Vec::new(),
            })
            .collect();
        let board = Board::new(6, 24, Milli(200_000)).unwrap();
        let config = MachineConfig::STRING_ART;
        let job = JobReplay::from_signals(&signals, board, &config).unwrap();
        let (canvas, summary) = draw(&job, 200);
        assert_eq!(summary, Summary::default());
        let at = |x: usize, y: usize| &canvas.rgb[(y * 200 + x) * 3..][..3];
        assert_eq!(at(100, 100), WOOD); // the centre
        assert_eq!(at(2, 2), [255; 3]); // a corner, off the board
        let path = std::env::temp_dir().join(format!("taut-picture-{}.png", std::process::id()));
        let summary = render_job(&signals, board, &config, &path).unwrap();
        assert_eq!(summary.holes, 0);
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        std::fs::remove_file(&path).unwrap();
    }
}
