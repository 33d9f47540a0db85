//! `taut text "Hello" --font futural --height-mm H -o out.gcode`: text in
//! a Hershey font as plotter G-code (seed 003 wrote its text this way).
//!
//! Capitals are `--height-mm` tall; each glyph advances by its own width
//! (the font's spacing, from the glyph's left and right edges); lines break
//! at a newline (or a typed `\n`) and, with `--wrap-mm`, between words; the
//! lines are 32 font units apart (Hershey's full height, top of the tallest
//! glyph to the bottom of the deepest). The pen lifts between strokes; the
//! text's ink starts at `--at` (its lower left corner).

use crate::args::{pair, Plotter};
use crate::hershey::{Font, Shape, BASE_LINE, CAP_LINE};
use crate::plot;
use crate::toolpath::Toolpath;
use crate::vectorize::trace::Polyline;
use std::path::PathBuf;
use taut_logic::machine::Machine;

/// Text in a Hershey font as plotter G-code, with a preview
#[derive(clap::Args, Debug)]
#[command(after_help = "\
Examples:
  taut text 'Hello' --height-mm 10 -o hello.gcode
  taut text 'Dear Ann,\\nthank you' --font scripts --height-mm 8 --wrap-mm 120 --machine whiteboard -o card.gcode

The preview goes to OUT's name with .preview.png unless --preview names it.")]
pub struct Cli {
    /// The text (a newline, or a typed \\n, breaks the line)
    pub text: String,
    /// The font
    #[arg(long, default_value = "futural")]
    pub font: String,
    /// Height of the capitals, mm
    #[arg(long, value_parser = crate::args::positive)]
    pub height_mm: f64,
    /// The G-code file
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// The machine the G-code is for
    #[arg(long, value_enum, default_value_t = Plotter::Flatbed)]
    pub machine: Plotter,
    /// Break lines between words before they pass this width, mm
    #[arg(long, value_parser = crate::args::positive)]
    pub wrap_mm: Option<f64>,
    /// The text's lower left corner X,Y, mm [default: the origin; the whiteboard: centred]
    #[arg(long, value_parser = pair, allow_hyphen_values = true)]
    pub at: Option<[f64; 2]>,
    /// Drawing feed, mm/min
    #[arg(long, default_value_t = 1500.0)]
    pub feed: f64,
    /// The preview picture (.png or .svg) [default: OUT.preview.png]
    #[arg(long)]
    pub preview: Option<PathBuf>,
}

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
    let text = text.replace("\\n", "\n");
    // Every character the fonts cannot draw, named once each.
    let mut missing: Vec<char> = Vec::new();
    for c in text.chars().filter(|&c| c != '\n') {
        if font.shape(c).is_none() && !missing.contains(&c) {
            missing.push(c);
        }
    }
    if !missing.is_empty() {
        let names: Vec<String> = missing
            .iter()
            .map(|c| format!("{c:?} (U+{:04X})", *c as u32))
            .collect();
        return Err(format!(
            "no glyph for {}: the Hershey fonts draw ASCII, Latin letters with accents, Greek, and Cyrillic А–Щ",
            names.join(", ")
        ));
    }
    let shapes: std::collections::HashMap<char, Shape> = text
        .chars()
        .filter(|&c| c != '\n')
        .filter_map(|c| Some((c, font.shape(c)?)))
        .collect();
    let advance = |c: char| shapes.get(&c).map_or(0.0, |g| (g.right - g.left) * scale);
    let lines = layout(&text, wrap_mm, advance);
    let pitch = f64::from(LINE_PITCH) * scale;
    let mut out: Vec<Polyline> = Vec::new();
    for (k, line) in lines.iter().enumerate() {
        let base = (lines.len() - 1 - k) as f64 * pitch;
        let mut x = 0.0;
        for c in line.chars() {
            let g = &shapes[&c];
            for s in &g.strokes {
                let pts = s.iter().map(|p| {
                    [
                        x + (p[0] - g.left) * scale,
                        base - (p[1] - f64::from(BASE_LINE)) * scale,
                    ]
                });
                out.push(pts.collect());
            }
            x += (g.right - g.left) * scale;
        }
    }
    let (lo, _) = crate::vectorize::bounds(&out);
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
pub fn run(cli: Cli) -> Result<(), String> {
    let font = Font::named(&cli.font)?;
    let machine = Machine::from(cli.machine);
    let (text, height, wrap, at, feed, out) = (
        cli.text,
        cli.height_mm,
        cli.wrap_mm,
        cli.at,
        cli.feed,
        cli.output,
    );
    let preview_path = cli
        .preview
        .unwrap_or_else(|| crate::output::derived(&out, "preview", "png"));
    crate::output::refuse_overwriting(&[], &[&out, &preview_path])?;
    crate::output::picture_extension(&preview_path)?;
    let placed = strokes(&font, &text, height, wrap, [0.0, 0.0])?;
    let (_, size) = crate::vectorize::bounds(&placed);
    let corner = at.unwrap_or_else(|| plot::default_corner(machine, size));
    let shifted = strokes(&font, &text, height, wrap, corner)?;
    let (gcode, path) = plot::plot(&shifted, machine, feed, &format!("taut text {text}"))?;
    let mut files = crate::output::Batch::new();
    files.add(&out, gcode.as_bytes());
    files.add(
        &preview_path,
        crate::render::bytes(&path, &preview_path, 1000)?,
    );
    files.commit()?;
    report(&path, &out, &preview_path);
    Ok(())
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
    fn accents_greek_and_cyrillic_are_drawn() {
        for (name, _) in FONTS {
            let font = Font::named(name).unwrap();
            let plain = strokes(&font, "e", 10.0, None, [0.0; 2]).unwrap();
            // A mark is one stroke more (two for ¨), above the letter.
            for (c, more) in [
                ('é', 1),
                ('è', 1),
                ('ê', 1),
                ('ě', 1),
                ('ë', 2),
                ('ę', 1),
                ('ȩ', 1),
            ] {
                let s = strokes(&font, &c.to_string(), 10.0, None, [0.0; 2]).unwrap();
                assert_eq!(s.len(), plain.len() + more, "{name} {c}");
            }
            let (_, top_e) = crate::vectorize::bounds(&plain);
            let (_, top_acute) =
                crate::vectorize::bounds(&strokes(&font, "é", 10.0, None, [0.0; 2]).unwrap());
            assert!(
                top_acute[1] > top_e[1] + 0.5,
                "{name}: the acute is above the e"
            );
            // í loses the i's dot: ı and the acute.
            let count = |t: &str| strokes(&font, t, 10.0, None, [0.0; 2]).unwrap().len();
            assert_eq!(count("í"), count("ı") + 1, "{name}");
            assert!(count("ı") < count("i"), "{name}");
            for text in [
                "Příliš žluťoučký kůň úpěl ďábelské ódy",
                "Împărați, ștergeți țările",
                "Þú ert",
                "ΑΒΓΔ αβγδ ως",
                "Привет, Щука",
            ] {
                let r = strokes(&font, text, 10.0, None, [0.0; 2]);
                match text.starts_with('Þ') {
                    true => assert!(r.unwrap_err().contains("'Þ' (U+00DE)"), "{name}"),
                    false => assert!(r.is_ok(), "{name} {text}: {r:?}"),
                }
            }
            // Ъ Ы Ь Э Ю Я are not in Hershey's Cyrillic.
            assert!(strokes(&font, "Я", 10.0, None, [0.0; 2])
                .unwrap_err()
                .contains("'Я' (U+042F)"));
        }
        // Greek Α is not Latin A in a complex font: the sets differ.
        let f = Font::named("timesr").unwrap();
        assert!(!f.shape('Σ').unwrap().strokes.is_empty());
        assert_ne!(f.shape('Ж'), f.shape('Z'));
    }

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
        let (lo, hi) = crate::vectorize::bounds(&s);
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
        let e = strokes(&font, "Straße 中", 10.0, None, [0.0; 2]).unwrap_err();
        assert!(
            e.starts_with("no glyph for 'ß' (U+00DF), '中' (U+4E2D): "),
            "{e}"
        );
    }
}
