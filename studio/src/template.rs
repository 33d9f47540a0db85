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

/// A 1:1 drilling template of a board (SVG), whole or tiled on pages
#[derive(clap::Args, Debug)]
#[command(after_help = "\
Examples:
  taut template --nails 250 --shape circle --radius-cm 40.2 -o template.svg
  taut template --nails 250 --shape circle --radius-cm 40.2 --paper A4 -o template.svg

With --paper the pages are template.A1.svg, template.A2.svg, … (rows A, B, …,
columns 1, 2, …). Print at 100 % (no fitting to the page): the 100 mm bar, or
each page's 20 mm square, checks the scale.")]
pub struct Cli {
    #[command(flatten)]
    pub board: crate::stringart::BoardArgs,
    /// The template (.svg); with --paper, the pages' names are made from it
    #[arg(short = 'o', long = "output")]
    pub output: std::path::PathBuf,
    /// Tile the template on pages of this paper: A4, letter, A3, … or WxH (mm)
    #[arg(long, value_parser = crate::vectorize::place::paper)]
    pub paper: Option<[f64; 2]>,
}

/// Room round the board for the numbers, mm.
const MARGIN_MM: f64 = 22.0;

/// The template of `spec`'s board as an SVG document.
pub fn template(spec: &Spec) -> Result<String, String> {
    Ok(drawing(spec)?.finish())
}

/// The template's drawing, 1:1 in mm.
fn drawing(spec: &Spec) -> Result<Svg, String> {
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
    Ok(s)
}

/// Room at each edge of a page no printer prints on, mm.
const PAGE_MARGIN_MM: f64 = 8.0;
/// The strip at the foot of each page for its label and scale square, mm.
const FOOT_MM: f64 = 26.0;
/// How far neighbouring pages overlap, mm.
pub const OVERLAP_MM: f64 = 12.0;
/// The scale check square, mm.
const CHECK_MM: f64 = 20.0;

/// The template tiled on pages of `paper` (mm, portrait): one SVG a page,
/// row by row from the top left. Each page shows its part of the drawing
/// 1:1 within the margins; where a neighbour overlaps it, a dashed line
/// marks the neighbour's edge (lay that page's edge on it) and crosses
/// mark the corners of the part for alignment; its foot names the page
/// and its neighbours and holds a 20 mm square to check the print's scale.
pub fn pages(spec: &Spec, paper: [f64; 2]) -> Result<Vec<String>, String> {
    let d = drawing(spec)?;
    let [vx, vy, vw, vh] = d.view;
    let part = [
        paper[0] - 2.0 * PAGE_MARGIN_MM,
        paper[1] - 2.0 * PAGE_MARGIN_MM - FOOT_MM,
    ];
    let step = [part[0] - OVERLAP_MM, part[1] - OVERLAP_MM];
    let count =
        |span: f64, part: f64, step: f64| 1 + ((span - part) / step).max(0.0).ceil() as usize;
    let (cols, rows) = (count(vw, part[0], step[0]), count(vh, part[1], step[1]));
    // The tiles' whole span, centred on the drawing.
    let total = [
        part[0] + (cols - 1) as f64 * step[0],
        part[1] + (rows - 1) as f64 * step[1],
    ];
    let origin = [vx - (total[0] - vw) / 2.0, vy - (total[1] - vh) / 2.0];
    let mut out = Vec::new();
    for r in 0..rows {
        for c in 0..cols {
            let at = [
                origin[0] + c as f64 * step[0],
                origin[1] + r as f64 * step[1],
            ];
            let mut p = Svg::new(0.0, 0.0, paper[0], paper[1]);
            let (m, pw, ph) = (PAGE_MARGIN_MM, part[0], part[1]);
            // Clipped to the part (a nested viewport alone is not
            // clipped by every viewer).
            p.push(&format!(
                "<defs><clipPath id=\"part\"><rect x=\"{m}\" y=\"{m}\" width=\"{pw}\" height=\"{ph}\"/></clipPath></defs>\n\
                 <g clip-path=\"url(#part)\"><svg x=\"{m}\" y=\"{m}\" width=\"{pw}\" height=\"{ph}\" viewBox=\"{} {} {pw} {ph}\">\n{}</svg></g>",
                num(at[0]),
                num(at[1]),
                d.body(),
                m = num(m),
                pw = num(pw),
                ph = num(ph),
            ));
            p.push(&format!(
                "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#999\" stroke-width=\"0.2\"/>",
                num(m), num(m), num(pw), num(ph)
            ));
            // The neighbours' edges on this page (dashed), with their names.
            let dash = "stroke=\"#c03020\" stroke-width=\"0.3\" stroke-dasharray=\"3 2\"";
            let label = |x: f64, y: f64, rot: f64, t: &str| {
                format!(
                    "<text x=\"{x}\" y=\"{y}\" transform=\"rotate({} {x} {y})\" font-family=\"sans-serif\" font-size=\"2.5\" fill=\"#c03020\">{t}</text>",
                    num(rot), x = num(x), y = num(y)
                )
            };
            let name = |r: usize, c: usize| format!("{}{}", (b'A' + r as u8) as char, c + 1);
            if c + 1 < cols {
                let x = m + pw - OVERLAP_MM;
                p.push(&format!(
                    "<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" {dash}/>",
                    num(x),
                    num(m),
                    num(x),
                    num(m + ph)
                ));
                p.push(&label(
                    x + 1.0,
                    m + 4.0,
                    90.0,
                    &format!("page {}'s left edge here", name(r, c + 1)),
                ));
            }
            if r + 1 < rows {
                let y = m + ph - OVERLAP_MM;
                p.push(&format!(
                    "<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" {dash}/>",
                    num(m),
                    num(y),
                    num(m + pw),
                    num(y)
                ));
                p.push(&label(
                    m + 2.0,
                    y - 1.0,
                    0.0,
                    &format!("page {}'s top edge here", name(r + 1, c)),
                ));
            }
            // Crosses at the corners of the part every page shares.
            for (x, y) in [(m, m), (m + pw, m), (m, m + ph), (m + pw, m + ph)] {
                p.push(&format!(
                    "<path d=\"M {} {} h 8 M {} {} v 8\" stroke=\"#000\" stroke-width=\"0.25\"/>",
                    num(x - 4.0),
                    num(y),
                    num(x),
                    num(y - 4.0)
                ));
            }
            let foot = m + ph + 4.0;
            p.push(&format!(
                "<rect x=\"{}\" y=\"{}\" width=\"{c}\" height=\"{c}\" fill=\"none\" stroke=\"#000\" stroke-width=\"0.3\"/>",
                num(m), num(foot), c = num(CHECK_MM)
            ));
            p.push(&format!(
                "<text x=\"{x}\" y=\"{}\" font-family=\"sans-serif\" font-size=\"4\">page {} of {} ({} rows × {} columns)</text>\n\
                 <text x=\"{x}\" y=\"{}\" font-family=\"sans-serif\" font-size=\"2.8\">the square must measure {} mm: print at 100 %, no fitting to the page</text>\n\
                 <text x=\"{x}\" y=\"{}\" font-family=\"sans-serif\" font-size=\"2.8\">pages overlap {} mm: lay the next page's edge on the dashed line, the crosses on each other</text>",
                num(foot + 5.0), name(r, c), rows * cols, rows, cols,
                num(foot + 11.0), num(CHECK_MM),
                num(foot + 16.0), num(OVERLAP_MM),
                x = num(m + CHECK_MM + 4.0),
            ));
            out.push(p.finish());
        }
    }
    Ok(out)
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
    let Some(paper) = cli.paper else {
        crate::output::refuse_overwriting(&[], &[&out])?;
        let doc = template(&spec)?;
        crate::output::write(&out, doc.as_bytes())?;
        println!(
            "written: {} (print at 100 %, no fitting to the page)",
            out.display()
        );
        return Ok(());
    };
    let pages = pages(&spec, paper)?;
    let total = pages.len();
    let mut files = crate::output::Batch::new();
    let mut names = Vec::new();
    let rows = pages_rows(&spec, paper)?;
    for (k, page) in pages.into_iter().enumerate() {
        let (r, c) = (k / (total / rows), k % (total / rows));
        let name = crate::output::derived(
            &out,
            &format!("{}{}", (b'A' + r as u8) as char, c + 1),
            "svg",
        );
        files.add(&name, page);
        names.push(name);
    }
    let refs: Vec<&std::path::Path> = names.iter().map(|n| n.as_path()).collect();
    crate::output::refuse_overwriting(&[], &refs)?;
    files.commit()?;
    println!(
        "written: {} pages, {} … {} (print each at 100 %, no fitting to the page)",
        names.len(),
        names[0].display(),
        names[names.len() - 1].display()
    );
    Ok(())
}

/// How many rows of pages the template takes.
fn pages_rows(spec: &Spec, paper: [f64; 2]) -> Result<usize, String> {
    let d = drawing(spec)?;
    let part = paper[1] - 2.0 * PAGE_MARGIN_MM - FOOT_MM;
    Ok(1 + ((d.view[3] - part) / (part - OVERLAP_MM)).max(0.0).ceil() as usize)
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
    fn tiled_pages_cover_the_template_with_overlap_and_a_scale_square() {
        let spec = Spec {
            shape: 0,
            nails: 250,
            radius_um: 402_000,
        };
        // 85 × 87 cm on A4 (194 × 255 mm a page, 12 mm overlap): 5 × 4.
        let p = pages(&spec, [210.0, 297.0]).unwrap();
        assert_eq!(p.len(), 20);
        assert_eq!(pages_rows(&spec, [210.0, 297.0]).unwrap(), 4);
        for (k, page) in p.iter().enumerate() {
            assert!(page.contains("width=\"210mm\" height=\"297mm\""));
            assert!(page.contains("the square must measure 20 mm"), "page {k}");
            assert!(page.contains("width=\"20\" height=\"20\""), "page {k}");
        }
        // The first page: neighbours right and below, marked.
        assert!(
            p[0].contains("page A2's left edge here") && p[0].contains("page B1's top edge here")
        );
        // The last: none.
        assert!(!p[19].contains("edge here"));
        // Every nail's cross is on some page, by its position in the part
        // each page shows.
        let board = spec.board().unwrap();
        let d = drawing(&spec).unwrap();
        let [vx, vy, vw, vh] = d.view;
        let part = [210.0 - 16.0, 297.0 - 16.0 - 26.0];
        let step = [part[0] - OVERLAP_MM, part[1] - OVERLAP_MM];
        let origin = [
            vx - (part[0] + 4.0 * step[0] - vw) / 2.0,
            vy - (part[1] + 3.0 * step[1] - vh) / 2.0,
        ];
        for i in 0..board.nails() {
            let [x, y] = nail_mm(&board, i);
            let (x, y) = (x, -y);
            let shown = (0..4).any(|r| {
                (0..5).any(|c| {
                    let at = [
                        origin[0] + c as f64 * step[0],
                        origin[1] + r as f64 * step[1],
                    ];
                    x > at[0] + 3.0
                        && x < at[0] + part[0] - 3.0
                        && y > at[1] + 3.0
                        && y < at[1] + part[1] - 3.0
                })
            });
            assert!(shown, "nail {i} at ({x:.1}, {y:.1}) is on no page whole");
        }
        // A small board fits one letter page.
        let small = Spec {
            shape: 0,
            nails: 24,
            radius_um: 60_000,
        };
        assert_eq!(pages(&small, [215.9, 279.4]).unwrap().len(), 1);
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
