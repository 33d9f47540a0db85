//! What the wound board will look like: `preview.png` (the thread at its
//! real width on the real board, anti-aliased: each thread leaves the share
//! of a pixel it does not cover) and `preview.svg` (the same, 1:1 in mm).
//! Seen from above: nail 0 to the right, numbering counter-clockwise.

use crate::board::nail_mm;
use crate::raster::{Canvas, Rgb};
use crate::svg::{num, points, Svg};
use std::f64::consts::TAU;
use taut_logic::geometry::{Board, NAIL_MARGIN_MM};

const GROUND: Rgb = [255, 255, 255];
const FACE: Rgb = [246, 240, 228];
const EDGE: Rgb = [150, 120, 90];
const NAIL: Rgb = [130, 130, 130];
const THREAD: Rgb = [20, 20, 20];
/// The nails' heads as drawn, mm.
const NAIL_RADIUS_MM: f64 = 1.0;

/// The board's edge as a closed polygon (a circle as 360 sides), mm: an
/// n-gon board's corners lie where its nail polygon's do, at radius R.
pub fn outline(board: &Board) -> Vec<[f64; 2]> {
    let r = f64::from(board.radius());
    let scale = r - f64::from(NAIL_MARGIN_MM);
    let ratio = f64::from(board.min_nail_radius()) / scale;
    let sides = match ratio < 1.0 - 1e-4 {
        true => (std::f64::consts::PI / ratio.acos()).round() as u32,
        false => 360,
    };
    (0..=sides)
        .map(|k| {
            let a = TAU * f64::from(k) / f64::from(sides);
            [r * a.cos(), r * a.sin()]
        })
        .collect()
}

/// The board and its thread on a `px`² picture.
pub fn png(board: &Board, pattern: &[u16], thread_mm: f64, px: usize) -> Canvas {
    let r = f64::from(board.radius());
    let mm_per_px = 2.0 * r * 1.04 / px as f64;
    let at = |p: [f64; 2]| {
        let c = px as f64 / 2.0;
        [(c + p[0] / mm_per_px) as f32, (c - p[1] / mm_per_px) as f32]
    };
    let mut c = Canvas::new(px, px, GROUND);
    fill_polygon(
        &mut c,
        &outline(board).iter().map(|&p| at(p)).collect::<Vec<_>>(),
        FACE,
    );
    let edge = outline(board);
    for w in edge.windows(2) {
        c.line(at(w[0]), at(w[1]), 1.5, EDGE, 1.0);
    }
    let width = (thread_mm / mm_per_px) as f32;
    let mut from = nail_mm(board, 0);
    for &n in pattern {
        let to = nail_mm(board, n);
        c.line(at(from), at(to), width, THREAD, 1.0);
        from = to;
    }
    let head = (NAIL_RADIUS_MM / mm_per_px).max(0.7) as f32;
    for i in 0..board.nails() {
        c.disc(at(nail_mm(board, i)), head, NAIL);
    }
    c
}

/// Fills a convex polygon given in pixels (anti-aliasing left to its edge
/// line).
fn fill_polygon(c: &mut Canvas, poly: &[[f32; 2]], color: Rgb) {
    let (lo, hi) = poly.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| {
        (lo.min(p[1]), hi.max(p[1]))
    });
    for y in lo.max(0.0) as usize..(hi.ceil() as usize).min(c.rows) {
        let yc = y as f32 + 0.5;
        let mut xs: Vec<f32> = poly
            .windows(2)
            .filter(|w| (w[0][1] <= yc) != (w[1][1] <= yc))
            .map(|w| w[0][0] + (yc - w[0][1]) / (w[1][1] - w[0][1]) * (w[1][0] - w[0][0]))
            .collect();
        xs.sort_by(f32::total_cmp);
        if let [a, .., b] = xs[..] {
            for x in a.max(0.0).round() as usize..(b.round() as usize).min(c.cols) {
                c.blend(y * c.cols + x, color, 1.0);
            }
        }
    }
}

/// The board, its nails (nail 0 marked) and the thread as one polyline of
/// the thread's width, in mm with y up as on the board.
pub fn svg(board: &Board, pattern: &[u16], thread_mm: f64) -> String {
    let r = f64::from(board.radius()) * 1.04;
    let mut s = Svg::new(-r, -r, 2.0 * r, 2.0 * r);
    let flip = |p: [f64; 2]| [p[0], -p[1]];
    s.push(&format!(
        "<polygon points=\"{}\" fill=\"#f6f0e4\" stroke=\"#96785a\" stroke-width=\"0.5\"/>",
        points(outline(board).into_iter().map(flip))
    ));
    let thread = std::iter::once(0).chain(pattern.iter().copied());
    s.push(&format!(
        "<polyline points=\"{}\" fill=\"none\" stroke=\"#141414\" stroke-width=\"{}\" stroke-linejoin=\"round\"/>",
        points(thread.map(|n| flip(nail_mm(board, n)))),
        num(thread_mm)
    ));
    for i in 0..board.nails() {
        let p = flip(nail_mm(board, i));
        let fill = if i == 0 { "#c03020" } else { "#828282" };
        s.push(&format!(
            "<circle cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"{fill}\"/>",
            num(p[0]),
            num(p[1]),
            num(NAIL_RADIUS_MM)
        ));
    }
    s.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use taut_logic::units::Milli;

    #[test]
    fn outlines_have_the_boards_corners() {
        let hex = Board::new(6, 24, Milli(200_000)).unwrap();
        let o = outline(&hex);
        assert_eq!(o.len(), 7);
        assert!((o[1][0] - 100.0).abs() < 1e-9);
        assert_eq!(
            outline(&Board::new(0, 30, Milli(200_000)).unwrap()).len(),
            361
        );
    }

    #[test]
    fn the_thread_darkens_the_png_along_its_chord_and_the_svg_lists_it() {
        let board = Board::new(0, 4, Milli(115_000)).unwrap();
        // 115 mm · 2 · 1.04 over 239.2 px: 1 mm a pixel; the chord 0 → 2
        // runs along the middle row.
        let c = png(&board, &[2], 3.0, 240);
        let at = |x: usize, y: usize| c.rgb[(y * 240 + x) * 3];
        assert!(at(60, 120) < 60, "{}", at(60, 120));
        assert!(at(120, 60) > 200, "off the thread: {}", at(120, 60));
        let doc = svg(&board, &[2, 1], 0.3);
        assert!(doc.contains("points=\"100,0 -100,0 0,-100\""), "{doc}");
        assert!(doc.contains("stroke-width=\"0.3\""));
        assert_eq!(doc.matches("<circle").count(), 4);
    }
}
