//! The Hershey vector fonts (public domain; `studio/fonts/README.md`),
//! embedded in James Hurt's `.jhf` format and parsed here.
//!
//! A glyph line: five columns of glyph number, three of vertex count, then
//! the vertices as letter pairs, each letter's distance from `R` the
//! coordinate (x right, y down). The first pair is the glyph's left and
//! right edge (its spacing); ` R` lifts the pen. Long glyphs run on over
//! the next lines. The ASCII fonts hold the characters from space to `~`
//! in order; capitals stand on the base line y = 9 and reach the cap line
//! y = −12.

/// The fonts `taut text --font` knows.
pub const FONTS: [(&str, &str); 7] = [
    ("futural", include_str!("../fonts/futural.jhf")),
    ("futuram", include_str!("../fonts/futuram.jhf")),
    ("rowmans", include_str!("../fonts/rowmans.jhf")),
    ("rowmand", include_str!("../fonts/rowmand.jhf")),
    ("timesr", include_str!("../fonts/timesr.jhf")),
    ("scripts", include_str!("../fonts/scripts.jhf")),
    ("gothiceng", include_str!("../fonts/gothiceng.jhf")),
];

/// Where capitals stand and reach, font units (y down).
pub const BASE_LINE: i32 = 9;
pub const CAP_LINE: i32 = -12;

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Glyph {
    /// The glyph's left and right edge: its advance is their difference.
    pub left: i32,
    pub right: i32,
    /// Pen-down runs, font units, y down.
    pub strokes: Vec<Vec<[i32; 2]>>,
}

pub struct Font {
    /// Glyphs from ASCII 32 (space) on.
    pub glyphs: Vec<Glyph>,
}

impl Font {
    pub fn named(name: &str) -> Result<Font, String> {
        let (_, data) = FONTS.iter().find(|(n, _)| *n == name).ok_or_else(|| {
            let names: Vec<&str> = FONTS.iter().map(|f| f.0).collect();
            format!("--font {name}: one of {}", names.join(", "))
        })?;
        Ok(Font {
            glyphs: parse(data)?,
        })
    }

    /// The glyph of a printable ASCII character.
    pub fn glyph(&self, c: char) -> Option<&Glyph> {
        let i = (c as u32).checked_sub(32)?;
        match c.is_ascii() {
            true => self.glyphs.get(i as usize),
            false => None,
        }
    }
}

/// Every glyph of a `.jhf` text.
pub fn parse(text: &str) -> Result<Vec<Glyph>, String> {
    let mut lines = text.lines().enumerate();
    let mut glyphs = Vec::new();
    while let Some((no, line)) = lines.next() {
        if line.trim().is_empty() {
            continue;
        }
        let bad = |what: &str| format!("font line {}: {what}", no + 1);
        let count: usize = line
            .get(5..8)
            .ok_or(bad("too short"))?
            .trim()
            .parse()
            .map_err(|_| bad("vertex count"))?;
        let mut pairs: String = line.get(8..).unwrap_or("").to_string();
        while pairs.len() < 2 * count {
            let (_, more) = lines.next().ok_or(bad("glyph cut short"))?;
            pairs.push_str(more);
        }
        let b = pairs.as_bytes();
        let at = |k: usize| {
            [
                i32::from(b[2 * k]) - i32::from(b'R'),
                i32::from(b[2 * k + 1]) - i32::from(b'R'),
            ]
        };
        let [left, right] = at(0);
        let mut strokes: Vec<Vec<[i32; 2]>> = vec![Vec::new()];
        for k in 1..count {
            if &b[2 * k..2 * k + 2] == b" R" {
                strokes.push(Vec::new());
            } else {
                strokes.last_mut().unwrap().push(at(k));
            }
        }
        strokes.retain(|s| !s.is_empty());
        glyphs.push(Glyph {
            left,
            right,
            strokes,
        });
    }
    Ok(glyphs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_font_holds_the_printable_ascii_characters() {
        for (name, _) in FONTS {
            let f = Font::named(name).unwrap();
            assert!(f.glyphs.len() >= 95, "{name}: {}", f.glyphs.len());
            let space = f.glyph(' ').unwrap();
            assert!(
                space.strokes.is_empty() && space.right > space.left,
                "{name}"
            );
            for c in '!'..='~' {
                let g = f.glyph(c).unwrap();
                assert!(!g.strokes.is_empty(), "{name} {c:?}");
                assert!(g.right > g.left, "{name} {c:?}");
            }
            // Capitals stand on the base line and reach the cap line.
            let h = f.glyph('H').unwrap();
            let ys: Vec<i32> = h.strokes.iter().flatten().map(|p| p[1]).collect();
            assert_eq!(
                (*ys.iter().min().unwrap(), *ys.iter().max().unwrap()),
                (CAP_LINE, BASE_LINE),
                "{name}"
            );
        }
        assert!(Font::named("comic")
            .err()
            .unwrap()
            .starts_with("--font comic: one of futural"));
    }

    #[test]
    fn a_glyph_by_hand_and_a_line_that_runs_on() {
        // futural's `!`: edges −5/5, a stroke down, pen up, the dot.
        let g = parse("12345  9MWRFRT RRYQZR[SZRY\n").unwrap();
        assert_eq!((g[0].left, g[0].right), (-5, 5));
        assert_eq!(
            g[0].strokes,
            vec![
                vec![[0, -12], [0, 2]],
                vec![[0, 7], [-1, 8], [0, 9], [1, 8], [0, 7]]
            ]
        );
        let wrapped = parse("12345  9MWRFRT RRYQZ\nR[SZRY\n").unwrap();
        assert_eq!(wrapped, g);
        assert!(parse("12345 40MW\n")
            .unwrap_err()
            .ends_with("glyph cut short"));
    }
}
