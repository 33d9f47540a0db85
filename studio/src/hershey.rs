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
//!
//! Beyond ASCII ([`Font::shape`]): Greek from Hershey's Greek sets (simplex
//! `greeks` beside the single-stroke fonts, complex `greekc` beside the
//! others), whose ASCII places hold the Greek alphabet in order (`A` Α …
//! `X` Ω, `a` α … `x` ω; final ς drawn as σ); Cyrillic from Hershey's
//! complex Cyrillic `cyrilc`, whose places `A`…`Z` hold А…Щ in the
//! alphabet's order (Hershey glyphs 2801–2826; Ъ Ы Ь Э Ю Я are not in the
//! set); Latin letters with diacritics composed from the base letter and
//! the mark drawn above or below it (Unicode's canonical decomposition:
//! é = e + ◌́), plus ø, ł and đ drawn as their base letter with a bar, ı as i without its dot.

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

/// Hershey's Greek and Cyrillic sets, in the ASCII places (see above).
const GREEK_SIMPLEX: &str = include_str!("../fonts/greeks.jhf");
const GREEK_COMPLEX: &str = include_str!("../fonts/greekc.jhf");
const CYRILLIC: &str = include_str!("../fonts/cyrilc.jhf");

/// The fonts drawn with one stroke, whose Greek is the simplex set.
const SIMPLEX: [&str; 3] = ["futural", "rowmans", "scripts"];

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
    /// The Greek and Cyrillic sets, in the same places.
    greek: Vec<Glyph>,
    cyrillic: Vec<Glyph>,
}

/// A glyph ready to draw: edges and strokes in font units (y down), marks
/// composed.
#[derive(Clone, Debug, PartialEq)]
pub struct Shape {
    pub left: f64,
    pub right: f64,
    pub strokes: Vec<Vec<[f64; 2]>>,
}

impl From<&Glyph> for Shape {
    fn from(g: &Glyph) -> Shape {
        Shape {
            left: f64::from(g.left),
            right: f64::from(g.right),
            strokes: g
                .strokes
                .iter()
                .map(|s| {
                    s.iter()
                        .map(|p| [f64::from(p[0]), f64::from(p[1])])
                        .collect()
                })
                .collect(),
        }
    }
}

impl Font {
    pub fn named(name: &str) -> Result<Font, String> {
        let (_, data) = FONTS.iter().find(|(n, _)| *n == name).ok_or_else(|| {
            let names: Vec<&str> = FONTS.iter().map(|f| f.0).collect();
            format!("--font {name}: one of {}", names.join(", "))
        })?;
        let greek = match SIMPLEX.contains(&name) {
            true => GREEK_SIMPLEX,
            false => GREEK_COMPLEX,
        };
        Ok(Font {
            glyphs: parse(data)?,
            greek: parse(greek)?,
            cyrillic: parse(CYRILLIC)?,
        })
    }

    /// The shape of any character the fonts can draw; `None` names a
    /// character they cannot.
    pub fn shape(&self, c: char) -> Option<Shape> {
        if let Some(g) = self.direct(c) {
            return Some(Shape::from(g));
        }
        if c == 'ı' {
            let mut s = Shape::from(self.direct('i')?);
            drop_dot(&mut s);
            return Some(s);
        }
        if let Some((base, bar)) = barred(c) {
            let mut s = Shape::from(self.direct(base)?);
            s.strokes.push(bar_across(&s, bar));
            return Some(s);
        }
        // A base letter and combining marks.
        let mut parts = Vec::new();
        unicode_normalization::char::decompose_canonical(c, |d| parts.push(d));
        let (&base, marks) = parts.split_first()?;
        if marks.is_empty() {
            return None;
        }
        let mut s = Shape::from(self.direct(base)?);
        // An i or j loses its dot under a mark above.
        if matches!(base, 'i' | 'j') && marks.iter().any(|m| mark(*m).is_some_and(|m| m.above)) {
            drop_dot(&mut s);
        }
        for &m in marks {
            let mk = mark(m)?;
            s.strokes.extend(place_mark(&s, &mk));
        }
        Some(s)
    }

    /// A glyph the fonts hold as it is.
    fn direct(&self, c: char) -> Option<&Glyph> {
        let u = c as u32;
        fn at(set: &[Glyph], ascii: u8) -> Option<&Glyph> {
            set.get(usize::from(ascii - 32))
                .filter(|g| !g.strokes.is_empty())
        }
        match u {
            0x20..=0x7E => self.glyphs.get((u - 32) as usize),
            // Α…Ρ, Σ…Ω (U+03A2 is unassigned).
            0x391..=0x3A9 if u != 0x3A2 => {
                at(&self.greek, b'A' + (u - 0x391 - u32::from(u > 0x3A2)) as u8)
            }
            // α…ω; final ς as σ.
            0x3B1..=0x3C9 => {
                let k = match u {
                    0x3C2 => 0x3C3 - 0x3B1 - 1,
                    _ => u - 0x3B1 - u32::from(u > 0x3C2),
                };
                at(&self.greek, b'a' + k as u8)
            }
            0x410..=0x429 => at(&self.cyrillic, b'A' + (u - 0x410) as u8),
            0x430..=0x449 => at(&self.cyrillic, b'a' + (u - 0x430) as u8),
            _ => None,
        }
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

/// Removes an i's or j's dot: the small strokes (4 units across at most)
/// wholly above the rest of the letter.
fn drop_dot(s: &mut Shape) {
    let small = |st: &Vec<[f64; 2]>| {
        let span = |k: usize| {
            let v = st.iter().map(|p| p[k]);
            v.clone().fold(f64::MIN, f64::max) - v.fold(f64::MAX, f64::min)
        };
        span(0) <= 4.0 && span(1) <= 4.0
    };
    let body_top = s
        .strokes
        .iter()
        .filter(|st| !small(st))
        .flatten()
        .map(|p| p[1])
        .fold(f64::MAX, f64::min);
    s.strokes
        .retain(|st| !(small(st) && st.iter().all(|p| p[1] < body_top)));
}

/// A diacritical mark: its strokes around its anchor, above the letter
/// (y up from the anchor, negative) or below it.
struct Mark {
    above: bool,
    /// Anchored at the right of the letter (the ogonek), not its middle.
    right: bool,
    strokes: Vec<Vec<[f64; 2]>>,
}

/// A small dot (Hershey's dots are diamonds of radius 1).
fn dot(x: f64, y: f64) -> Vec<[f64; 2]> {
    vec![
        [x, y - 1.0],
        [x + 1.0, y],
        [x, y + 1.0],
        [x - 1.0, y],
        [x, y - 1.0],
    ]
}

/// The marks the composed letters use (Unicode's combining marks).
fn mark(c: char) -> Option<Mark> {
    let (above, right, strokes): (bool, bool, Vec<Vec<[f64; 2]>>) = match c {
        '\u{300}' => (true, false, vec![vec![[-1.5, -4.0], [1.0, 0.0]]]),
        '\u{301}' => (true, false, vec![vec![[1.5, -4.0], [-1.0, 0.0]]]),
        '\u{302}' => (
            true,
            false,
            vec![vec![[-3.0, 0.0], [0.0, -3.0], [3.0, 0.0]]],
        ),
        '\u{303}' => (
            true,
            false,
            vec![vec![
                [-3.5, -0.5],
                [-2.0, -2.0],
                [-0.5, -1.5],
                [0.5, -0.5],
                [2.0, 0.0],
                [3.5, -1.5],
            ]],
        ),
        '\u{304}' => (true, false, vec![vec![[-3.0, -1.0], [3.0, -1.0]]]),
        '\u{306}' => (
            true,
            false,
            vec![vec![
                [-3.0, -3.0],
                [-2.0, -1.0],
                [0.0, 0.0],
                [2.0, -1.0],
                [3.0, -3.0],
            ]],
        ),
        '\u{307}' => (true, false, vec![dot(0.0, -1.0)]),
        '\u{308}' => (true, false, vec![dot(-2.5, -1.0), dot(2.5, -1.0)]),
        '\u{30A}' => (
            true,
            false,
            vec![vec![
                [0.0, -3.0],
                [1.5, -1.5],
                [0.0, 0.0],
                [-1.5, -1.5],
                [0.0, -3.0],
            ]],
        ),
        '\u{30B}' => (
            true,
            false,
            vec![
                vec![[-0.5, -4.0], [-2.5, 0.0]],
                vec![[3.0, -4.0], [1.0, 0.0]],
            ],
        ),
        '\u{30C}' => (
            true,
            false,
            vec![vec![[-3.0, -3.0], [0.0, 0.0], [3.0, -3.0]]],
        ),
        '\u{326}' => (
            false,
            false,
            vec![vec![[0.0, 1.0], [0.5, 2.0], [0.0, 3.0], [-1.0, 4.0]]],
        ),
        '\u{327}' => (
            false,
            false,
            vec![vec![
                [0.0, 0.0],
                [0.0, 1.5],
                [1.5, 2.5],
                [0.5, 4.0],
                [-1.5, 4.0],
            ]],
        ),
        '\u{328}' => (
            false,
            true,
            vec![vec![
                [0.0, 0.0],
                [-2.0, 1.5],
                [-2.0, 3.0],
                [-0.5, 4.0],
                [1.0, 3.5],
            ]],
        ),
        _ => return None,
    };
    Some(Mark {
        above,
        right,
        strokes,
    })
}

/// The mark's strokes over (or under) the shape's ink: 1.5 units clear of
/// its top, or hanging from the base line.
fn place_mark(s: &Shape, m: &Mark) -> Vec<Vec<[f64; 2]>> {
    let pts = s.strokes.iter().flatten();
    let (lo, hi) = pts.fold(([f64::MAX; 2], [f64::MIN; 2]), |(lo, hi), p| {
        (
            [lo[0].min(p[0]), lo[1].min(p[1])],
            [hi[0].max(p[0]), hi[1].max(p[1])],
        )
    });
    let (lo, hi) = match lo[0] <= hi[0] {
        true => (lo, hi),
        false => ([s.left, 0.0], [s.right, 0.0]),
    };
    let x = match m.right {
        true => hi[0] - 1.0,
        false => (lo[0] + hi[0]) / 2.0,
    };
    let y = match m.above {
        true => lo[1] - 1.5,
        false => f64::from(BASE_LINE),
    };
    m.strokes
        .iter()
        .map(|st| st.iter().map(|p| [x + p[0], y + p[1]]).collect())
        .collect()
}

/// Letters drawn as their base letter with a bar: the bar's slope (0
/// flat, 1 a slash).
fn barred(c: char) -> Option<(char, f64)> {
    Some(match c {
        'ø' => ('o', 1.0),
        'Ø' => ('O', 1.0),
        'ł' => ('l', 0.6),
        'Ł' => ('L', 0.6),
        'đ' => ('d', 0.0),
        'Đ' => ('D', 0.0),
        _ => return None,
    })
}

/// The bar across a shape's ink (a slash through its middle, or a flat
/// bar at 60 % of its height).
fn bar_across(s: &Shape, slope: f64) -> Vec<[f64; 2]> {
    let pts: Vec<[f64; 2]> = s.strokes.iter().flatten().copied().collect();
    let (x0, x1) = (
        pts.iter().map(|p| p[0]).fold(f64::MAX, f64::min),
        pts.iter().map(|p| p[0]).fold(f64::MIN, f64::max),
    );
    let (y0, y1) = (
        pts.iter().map(|p| p[1]).fold(f64::MAX, f64::min),
        pts.iter().map(|p| p[1]).fold(f64::MIN, f64::max),
    );
    let (cx, cy) = ((x0 + x1) / 2.0, y0 + 0.45 * (y1 - y0));
    let half = ((x1 - x0) / 2.0 + 1.5).max(3.0);
    [
        [cx - half, cy + slope * half],
        [cx + half, cy - slope * half],
    ]
    .to_vec()
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
