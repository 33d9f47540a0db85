//! A toolpath as a picture, PNG or SVG: the pen down solid, its travel
//! dashed (`taut preview`, and the previews `vectorize`, `text` and the
//! studio write beside their G-code).

use crate::output::picture_extension;
use crate::raster::{Canvas, Rgb};
use crate::svg::{num, points, Svg};
use crate::toolpath::Toolpath;
use std::path::Path;

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
    Ok(match picture_extension(out)?.as_str() {
        "svg" => svg(path).into_bytes(),
        _ => png(path, px).png(),
    })
}

/// Writes the toolpath as PNG or SVG, by `out`'s extension, atomically.
pub fn save(path: &Toolpath, out: &Path, px: usize) -> Result<(), String> {
    crate::output::write(out, &bytes(path, out, px)?)
}
