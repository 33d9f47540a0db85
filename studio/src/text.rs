//! `taut text "Hello" --font futural --height-mm H -o out.gcode`: text in
//! a Hershey font as plotter G-code (seed 003 wrote its text this way).
//!
//! Capitals are `--height-mm` tall; each glyph advances by its own width
//! (the font's spacing, from the glyph's left and right edges); lines break
//! at a newline (or a typed `\n`) and, with `--wrap-mm`, between words; the
//! lines are 32 font units apart (Hershey's full height, top of the tallest
//! glyph to the bottom of the deepest). The pen lifts between strokes; the
//! text's ink starts at `--at` (its lower left corner).

use crate::args::Args;
use crate::hershey::{Font, BASE_LINE, CAP_LINE};
use crate::toolpath::Toolpath;
use crate::vectorize::trace::Polyline;
use crate::{plot, preview};
use std::path::PathBuf;
use taut_logic::machine::Machine;

pub const USAGE: &str = "\
taut text TEXT --font futural --height-mm H -o out.gcode [--machine flatbed]
    [--wrap-mm W] [--at X,Y] [--feed 1500] [--preview out.png]";

/// Lines are this many font units apart.
const LINE_PITCH: i32 = 32;

/// `text` laid out in `font`: strokes in mm, the lower left corner of all
/// their ink at `at` (a glyph may reach past its left edge, a descender
/// below the base line). Errors name a character the font lacks.
pub fn strokes(
    font: &Font,
    text: &str,
    height_mm: f64,
    wrap_mm: Option<f64>,
    at: [f64; 2],
) -> Result<Vec<Polyline>, String> {
    if height_mm.is_nan() || height_mm <= 0.0 {
        return Err("--height-mm must be above 0".into());
    }
    let scale = height_mm / f64::from(BASE_LINE - CAP_LINE);
    let advance = |c: char| font.glyph(c).map(|g| f64::from(g.right - g.left) * scale);
    if let Some(c) = text.chars().find(|&c| c != '\n' && advance(c).is_none()) {
        return Err(format!("{c:?} is not in the font (printable ASCII only)"));
    }
    let lines = layout(&text.replace("\\n", "\n"), wrap_mm, |c| {
        advance(c).unwrap_or(0.0)
    });
    let pitch = f64::from(LINE_PITCH) * scale;
    let mut out: Vec<Polyline> = Vec::new();
    for (k, line) in lines.iter().enumerate() {
        let base = (lines.len() - 1 - k) as f64 * pitch;
        let mut x = 0.0;
        for c in line.chars() {
            let g = font.glyph(c).expect("checked above");
            for s in &g.strokes {
                let pts = s.iter().map(|p| {
                    [
                        x + f64::from(p[0] - g.left) * scale,
                        base - f64::from(p[1] - BASE_LINE) * scale,
                    ]
                });
                out.push(pts.collect());
            }
            x += f64::from(g.right - g.left) * scale;
        }
    }
    let (lo, _) = extent(&out);
    for p in out.iter_mut().flatten() {
        *p = [p[0] - lo[0] + at[0], p[1] - lo[1] + at[1]];
    }
    Ok(out)
}

/// The lines: at each newline, and between words where a line would pass
/// `wrap` mm (a word longer than that stands alone).
fn layout(text: &str, wrap: Option<f64>, advance: impl Fn(char) -> f64) -> Vec<String> {
    let width = |s: &str| s.chars().map(&advance).sum::<f64>();
    let mut lines = Vec::new();
    for para in text.split('\n') {
        let Some(limit) = wrap else {
            lines.push(para.to_string());
            continue;
        };
        let mut line = String::new();
        for word in para.split(' ') {
            let joined = match line.is_empty() {
                true => word.to_string(),
                false => format!("{line} {word}"),
            };
            if width(&joined) > limit && !line.is_empty() {
                lines.push(std::mem::replace(&mut line, word.to_string()));
            } else {
                line = joined;
            }
        }
        lines.push(line);
    }
    lines
}

/// `taut text …` from the command line.
pub fn run(mut args: Args) -> Result<(), String> {
    let text = args.positional("TEXT")?;
    let font = Font::named(&args.value("font").unwrap_or_else(|| "futural".into()))?;
    let height = args.number("height-mm", f64::NAN)?;
    let machine = match args.value("machine") {
        Some(m) => plot::machine(&m)?,
        None => Machine::Flatbed,
    };
    let wrap = args
        .value("wrap-mm")
        .map(|w| {
            w.parse::<f64>()
                .map_err(|_| format!("--wrap-mm {w}: not a number"))
        })
        .transpose()?;
    let at = args.pair("at")?;
    let feed = args.number("feed", 1500.0)?;
    let out = PathBuf::from(args.required("o")?);
    let preview_path = args
        .value("preview")
        .map(PathBuf::from)
        .unwrap_or_else(|| out.with_extension("png"));
    args.finish()?;
    let placed = strokes(&font, &text, height, wrap, [0.0, 0.0])?;
    let (_, size) = extent(&placed);
    let corner = at.unwrap_or_else(|| plot::default_corner(machine, size));
    let shifted = strokes(&font, &text, height, wrap, corner)?;
    let (gcode, path) = plot::plot(&shifted, machine, feed, &format!("taut text {text}"))?;
    std::fs::write(&out, &gcode).map_err(|e| format!("{}: {e}", out.display()))?;
    preview::save(&path, &preview_path, 1000)?;
    report(&path, &out, &preview_path);
    Ok(())
}

fn extent(strokes: &[Polyline]) -> ([f64; 2], [f64; 2]) {
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

fn report(path: &Toolpath, out: &std::path::Path, preview: &std::path::Path) {
    let (lo, hi) = path.bounds();
    let (down, up) = path.lengths();
    println!(
        "text: X {:.1}…{:.1}, Y {:.1}…{:.1} mm; pen down {down:.0} mm, up {up:.0} mm\n  written: {}, {}",
        lo[0],
        hi[0],
        lo[1],
        hi[1],
        out.display(),
        preview.display()
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hershey::FONTS;

    #[test]
    fn every_printable_glyph_of_every_font_plots() {
        // Ten characters a line.
        let chars: Vec<char> = (' '..='~').collect();
        let all: Vec<String> = chars.chunks(10).map(|c| c.iter().collect()).collect();
        let all = all.join("\n");
        for (name, _) in FONTS {
            let font = Font::named(name).unwrap();
            let s = strokes(&font, &all, 5.0, None, [0.0, 0.0]).unwrap();
            // Every glyph but the space draws at least one stroke.
            let drawn: usize = ('!'..='~')
                .map(|c| font.glyph(c).unwrap().strokes.len())
                .sum();
            assert_eq!(s.len(), drawn, "{name}");
            let (g, path) = plot::plot(&s, Machine::Flatbed, 1500.0, name).unwrap();
            assert!(path.lengths().0 > 0.0 && g.lines().count() > 95, "{name}");
        }
    }

    #[test]
    fn capitals_have_the_height_and_glyphs_their_widths() {
        let font = Font::named("futural").unwrap();
        let s = strokes(&font, "HH", 10.0, None, [3.0, 4.0]).unwrap();
        let (lo, hi) = extent(&s);
        let unit = 10.0 / 21.0;
        assert_eq!(lo, [3.0, 4.0]);
        assert!((hi[1] - lo[1] - 10.0).abs() < 1e-9, "{lo:?} {hi:?}");
        // The second H starts one H's advance (22 units) after the first.
        let h = font.glyph('H').unwrap();
        assert_eq!(h.right - h.left, 22);
        assert!(
            (s[3][0][0] - s[0][0][0] - 22.0 * unit).abs() < 1e-9,
            "{:?}",
            s[3]
        );
        // From the first H's left bar to the second's right bar: one
        // advance and the 14 units between an H's bars.
        assert!((hi[0] - lo[0] - (22.0 + 14.0) * unit).abs() < 1e-9);
    }

    #[test]
    fn lines_break_at_newlines_and_words_wrap() {
        let font = Font::named("futural").unwrap();
        let one = strokes(&font, "I", 10.0, None, [0.0, 0.0]).unwrap();
        let two = strokes(&font, "I\\nI", 10.0, None, [0.0, 0.0]).unwrap();
        // The first line sits one pitch (32 units) above the second.
        assert!((two[0][0][1] - two[1][0][1] - 32.0 * 10.0 / 21.0).abs() < 1e-9);
        assert_eq!(two[1], one[0]);
        let adv = |c: char| if c == ' ' { 1.0 } else { 2.0 };
        assert_eq!(layout("ab cd ef", Some(9.0), adv), ["ab cd", "ef"]);
        assert_eq!(layout("abcdefgh ij", Some(5.0), adv), ["abcdefgh", "ij"]);
        assert!(strokes(&font, "é", 10.0, None, [0.0; 2])
            .unwrap_err()
            .starts_with("'é' is not in the font"));
    }
}
