//! `taut template --nails N --shape circle|<n> --radius-cm R -o
//! template.svg`: a 1:1 printable drilling template — for boards built by
//! hand, or to check the machine's drilling.
//!
//! Every nail's centre (the machine's own positions) is a cross, numbered
//! outwards (every k-th nail where numbers would crowd); nail 0 is red,
//! with the line from the centre that is base angle 0 and an arrow the way
//! the numbers go (counter-clockwise, seen from above). A 100 mm bar
//! checks the printer's scale.

use crate::board::nail_mm;
use crate::stringart::card::Spec;
use crate::stringart::picture::outline;
use crate::svg::{num, points, Svg};
use std::f64::consts::TAU;
use taut_logic::geometry::Board;

/// A 1:1 drilling template of a board (SVG)
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Example:\n  taut template --nails 250 --shape circle --radius-cm 40.2 -o template.svg\n\n\
Print at 100 % (no fitting to the page); the 100 mm bar checks the scale."
)]
pub struct Cli {
    #[command(flatten)]
    pub board: crate::stringart::BoardArgs,
    /// The template (.svg)
    #[arg(short = 'o', long = "output")]
    pub output: std::path::PathBuf,
}

/// Room round the board for the numbers, mm.
const MARGIN_MM: f64 = 22.0;

/// The template of `spec`'s board as an SVG document.
pub fn template(spec: &Spec) -> Result<String, String> {
    let board = spec.board()?;
    let r = f64::from(board.radius());
    let bar = if r >= 60.0 { 100.0 } else { 20.0 };
    let (half, below) = (r + MARGIN_MM, 24.0);
    let mut s = Svg::new(-half, -half, 2.0 * half, 2.0 * half + below);
    let flip = |p: [f64; 2]| [p[0], -p[1]];
    s.push(&format!(
        "<polygon points=\"{}\" fill=\"none\" stroke=\"#888\" stroke-width=\"0.3\"/>",
        points(outline(&board).into_iter().map(flip))
    ));
    // The centring pin.
    s.push("<path d=\"M -6 0 H 6 M 0 -6 V 6\" stroke=\"#000\" stroke-width=\"0.2\"/>");
    s.push("<circle r=\"3\" fill=\"none\" stroke=\"#000\" stroke-width=\"0.2\"/>");
    let spacing = nail_spacing(&board);
    let cross = (0.35 * spacing).clamp(0.3, 3.0);
    let (font, every) = labels(spacing);
    let mut crosses = String::new();
    for i in 0..board.nails() {
        let [x, y] = flip(nail_mm(&board, i));
        crosses += &format!(
            "M {} {} h {} M {} {} v {} ",
            num(x - cross),
            num(y),
            num(2.0 * cross),
            num(x),
            num(y - cross),
            num(2.0 * cross)
        );
        if i % every == 0 {
            s.push(&label(&board, i, font, cross));
        }
    }
    s.push(&format!(
        "<path d=\"{crosses}\" stroke=\"#000\" stroke-width=\"0.15\"/>"
    ));
    let zero = flip(nail_mm(&board, 0));
    s.push(&format!(
        "<line x1=\"0\" y1=\"0\" x2=\"{}\" y2=\"0\" stroke=\"#c03020\" stroke-width=\"0.25\" stroke-dasharray=\"3 2\"/>",
        num(zero[0] - 2.0 * cross)
    ));
    s.push(&format!(
        "<circle cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"none\" stroke=\"#c03020\" stroke-width=\"0.4\"/>",
        num(zero[0]),
        num(zero[1]),
        num(1.5 * cross + 0.5)
    ));
    s.push(&numbering_arrow(&board, font));
    let bottom = half + 6.0;
    s.push(&format!(
        "<path d=\"M {x} {bottom} h {bar} M {x} {} v 4 M {} {} v 4\" stroke=\"#000\" stroke-width=\"0.4\"/>",
        num(bottom - 2.0),
        num(-half + 5.0 + bar),
        num(bottom - 2.0),
        x = num(-half + 5.0),
        bar = num(bar),
        bottom = num(bottom),
    ));
    let shape = match spec.shape {
        0 => "circle".to_string(),
        n => format!("{n}-gon"),
    };
    s.push(&format!(
        "<text x=\"{}\" y=\"{}\" font-family=\"sans-serif\" font-size=\"3.5\">{bar} mm: check the print is 1:1. \
         taut drilling template: {shape}, {} nails, R {} cm (nails {} mm inside the edge)</text>",
        num(-half + 5.0),
        num(bottom + 8.0),
        board.nails(),
        num(r / 10.0),
        num(f64::from(taut_logic::geometry::NAIL_MARGIN_MM)),
    ));
    Ok(s.finish())
}

/// The least distance between neighbouring nails, mm.
fn nail_spacing(board: &Board) -> f64 {
    (0..board.nails())
        .map(|i| {
            let (p, q) = (nail_mm(board, i), nail_mm(board, (i + 1) % board.nails()));
            (p[0] - q[0]).hypot(p[1] - q[1])
        })
        .fold(f64::MAX, f64::min)
}

/// The numbers' size, mm, and which nails get one (every k-th): as large
/// as the spacing allows, 1.5 to 5 mm.
fn labels(spacing: f64) -> (f64, u16) {
    let font = (0.8 * spacing).clamp(1.5, 5.0);
    let every = [1u16, 2, 5, 10, 20, 50, 100, 200, 500, 1000]
        .into_iter()
        .find(|&k| f64::from(k) * spacing >= 1.2 * font)
        .unwrap_or(1000);
    (font, every)
}

/// Nail `i`'s number, outside the ring along its radius, upright on the
/// left half.
fn label(board: &Board, i: u16, font: f64, cross: f64) -> String {
    let [x, y] = nail_mm(board, i);
    let a = y.atan2(x);
    let r = x.hypot(y) + cross + 1.0;
    let (px, py) = (r * a.cos(), -r * a.sin());
    let deg = -a.to_degrees();
    let left = a.cos() < -1e-9;
    let (rotate, anchor) = match left {
        true => (deg + 180.0, "end"),
        false => (deg, "start"),
    };
    let color = if i == 0 { "#c03020" } else { "#000" };
    format!(
        "<text x=\"{x}\" y=\"{y}\" transform=\"rotate({} {x} {y})\" font-family=\"sans-serif\" font-size=\"{}\" \
         text-anchor=\"{anchor}\" dominant-baseline=\"central\" fill=\"{color}\">{i}</text>",
        num(rotate),
        num(font),
        x = num(px),
        y = num(py),
    )
}

/// A short arc inside the ring from nail 0 the way the numbers go, with
/// its head.
fn numbering_arrow(board: &Board, font: f64) -> String {
    let r = f64::from(board.min_nail_radius()) - 3.0 * font - 4.0;
    let sweep = (40.0 / r).min(TAU / 8.0);
    let arc: Vec<[f64; 2]> = (0..=16)
        .map(|k| {
            let a = sweep * f64::from(k) / 16.0;
            [r * a.cos(), -r * a.sin()]
        })
        .collect();
    let end = arc[16];
    // The head points along the arc (counter-clockwise: up the page at 0°).
    let (t, n) = ([-sweep.sin(), -sweep.cos()], [sweep.cos(), -sweep.sin()]);
    let head = [
        [
            end[0] - 3.0 * t[0] + 1.5 * n[0],
            end[1] - 3.0 * t[1] + 1.5 * n[1],
        ],
        end,
        [
            end[0] - 3.0 * t[0] - 1.5 * n[0],
            end[1] - 3.0 * t[1] - 1.5 * n[1],
        ],
    ];
    format!(
        "<polyline points=\"{}\" fill=\"none\" stroke=\"#c03020\" stroke-width=\"0.4\"/>\n\
         <polyline points=\"{}\" fill=\"none\" stroke=\"#c03020\" stroke-width=\"0.4\"/>\n\
         <text x=\"{}\" y=\"{}\" font-family=\"sans-serif\" font-size=\"3\" fill=\"#c03020\" text-anchor=\"end\">nail 0, numbers go this way</text>",
        points(arc),
        points(head),
        num(r - 3.0),
        num(3.0),
    )
}

/// `taut template …` from the command line.
pub fn run(cli: Cli) -> Result<(), String> {
    let spec = cli.board.spec()?;
    let out = cli.output;
    crate::output::refuse_overwriting(&[], &[&out])?;
    let doc = template(&spec)?;
    crate::output::write(&out, doc.as_bytes())?;
    println!(
        "written: {} (print at 100 %, no fitting to the page)",
        out.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_nail_is_a_cross_at_the_machines_position() {
        let spec = Spec {
            shape: 6,
            nails: 24,
            radius_um: 200_000,
        };
        let doc = template(&spec).unwrap();
        // 1:1: the page is in millimetres.
        assert!(doc.contains("width=\"444mm\""), "{}", &doc[..200]);
        let board = spec.board().unwrap();
        for i in 0..24 {
            let [x, y] = nail_mm(&board, i);
            let c = (0.35 * nail_spacing(&board)).clamp(0.3, 3.0);
            let cross = format!("M {} {} h", num(x - c), num(-y));
            assert!(doc.contains(&cross), "nail {i}: {cross}");
            assert!(doc.contains(&format!(">{i}</text>")), "nail {i}'s number");
        }
        assert!(doc.contains("100 mm: check the print is 1:1"));
        assert!(doc.contains("nail 0, numbers go this way"));
    }

    #[test]
    fn crowded_numbers_thin_out() {
        assert_eq!(labels(9.7), (5.0, 1));
        assert_eq!(labels(0.24), (1.5, 10));
        // The densest boards the firmware's needle passes (~3.7 mm apart)
        // keep every number; denser ones are refused.
        let doc = template(&Spec {
            shape: 0,
            nails: 680,
            radius_um: 402_000,
        })
        .unwrap();
        assert!(doc.contains(">678</text>") && doc.contains(">679</text>"));
        let dense = Spec {
            shape: 0,
            nails: 10_000,
            radius_um: 402_000,
        };
        assert!(template(&dense)
            .unwrap_err()
            .contains("too close for the needle"));
    }

    #[test]
    fn impossible_boards_are_refused() {
        let e = template(&Spec {
            shape: 0,
            nails: 2,
            radius_um: 200_000,
        })
        .unwrap_err();
        assert_eq!(e, "param.txt:2:17: expected 3 to 10000");
    }
}
