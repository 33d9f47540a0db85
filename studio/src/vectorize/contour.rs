//! Iso-lines of a grey picture at sub-pixel precision: marching squares
//! over the pixel centres, each crossing placed on its cell side by linear
//! interpolation between the two grey levels (so a blurred edge is found
//! where the grey passes the level, not at a pixel's border). The raster is
//! padded with white all round, so every line closes; the region darker
//! than the level lies to the left of each loop as drawn (x right, y
//! down), and loops nest: even-odd filling gives the dark region.

use super::trace::Polyline;
use std::collections::HashMap;

/// A cell side: the cell (x, y) of the padded grid and the side 0 top,
/// 1 right, 2 bottom, 3 left.
type Side = (usize, usize, u8);

/// The closed iso-lines where `field` (row-major, `w` × `h`, top row
/// first) passes `level`, in pixel coordinates (pixel centres at + 0.5).
pub fn iso(field: &[f32], w: usize, h: usize, level: f32) -> Vec<Polyline> {
    // Corner (x, y) of the padded grid is pixel (x − 1, y − 1); outside
    // the picture is white, above any level a picture can be dark at.
    let white = level.max(1.0) + 1.0;
    let value = |x: usize, y: usize| match x >= 1 && y >= 1 && x <= w && y <= h {
        true => field[(y - 1) * w + (x - 1)],
        false => white,
    };
    let dark = |x: usize, y: usize| value(x, y) < level;
    let mut next: HashMap<Side, Side> = HashMap::new();
    for y in 0..=h {
        for x in 0..=w {
            let case = dark(x, y) as u8
                | (dark(x + 1, y) as u8) << 1
                | (dark(x + 1, y + 1) as u8) << 2
                | (dark(x, y + 1) as u8) << 3;
            // Dark on the left of each directed segment. The two saddles
            // (5, 10) are split by the cell's mean, as the picture would
            // be between its four pixels.
            let centre_dark = || {
                (value(x, y) + value(x + 1, y) + value(x + 1, y + 1) + value(x, y + 1)) / 4.0
                    < level
            };
            let segments: &[(u8, u8)] = match case {
                1 => &[(3, 0)],
                2 => &[(0, 1)],
                3 => &[(3, 1)],
                4 => &[(1, 2)],
                5 if centre_dark() => &[(3, 2), (1, 0)],
                5 => &[(3, 0), (1, 2)],
                6 => &[(0, 2)],
                7 => &[(3, 2)],
                8 => &[(2, 3)],
                9 => &[(2, 0)],
                10 if centre_dark() => &[(2, 1), (0, 3)],
                10 => &[(0, 1), (2, 3)],
                11 => &[(2, 1)],
                12 => &[(1, 3)],
                13 => &[(1, 0)],
                14 => &[(0, 3)],
                _ => &[],
            };
            for &(a, b) in segments {
                next.insert((x, y, a), (x, y, b));
            }
        }
    }
    // Leaving a cell by side b is entering its neighbour by the opposite.
    let enter = |(x, y, side): Side| match side {
        0 => (x, y.wrapping_sub(1), 2),
        1 => (x + 1, y, 3),
        2 => (x, y + 1, 0),
        _ => (x.wrapping_sub(1), y, 1),
    };
    let point = |(x, y, side): Side| {
        // The side's two corners, then where the level lies between them.
        let (a, b) = match side {
            0 => ((x, y), (x + 1, y)),
            1 => ((x + 1, y), (x + 1, y + 1)),
            2 => ((x, y + 1), (x + 1, y + 1)),
            _ => ((x, y), (x, y + 1)),
        };
        let (va, vb) = (value(a.0, a.1), value(b.0, b.1));
        let t = match (vb - va).abs() > 1e-12 {
            true => f64::from((level - va) / (vb - va)).clamp(0.0, 1.0),
            false => 0.5,
        };
        // Padded corner (x, y) is the centre of pixel (x − 1, y − 1).
        let at = |c: (usize, usize)| [c.0 as f64 - 0.5, c.1 as f64 - 0.5];
        let (pa, pb) = (at(a), at(b));
        [pa[0] + t * (pb[0] - pa[0]), pa[1] + t * (pb[1] - pa[1])]
    };
    let mut starts: Vec<Side> = next.keys().copied().collect();
    starts.sort_unstable();
    let mut out = Vec::new();
    for start in starts {
        if !next.contains_key(&start) {
            continue;
        }
        let mut ring = vec![point(start)];
        let mut at = start;
        while let Some(exit) = next.remove(&at) {
            ring.push(point(exit));
            at = enter(exit);
        }
        out.push(ring);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vectorize::simplify::simplify;

    #[test]
    fn a_dark_block_has_one_closed_outline_halfway_between_pixel_centres() {
        let (w, h) = (10, 8);
        let mut f = vec![1.0f32; w * h];
        for y in 2..5 {
            for x in 3..7 {
                f[y * w + x] = 0.0;
            }
        }
        let o = iso(&f, w, h, 0.5);
        assert_eq!(o.len(), 1);
        let ring = &o[0];
        assert_eq!(ring.first(), ring.last());
        let xs: Vec<f64> = ring.iter().map(|p| p[0]).collect();
        let lo = xs.iter().cloned().fold(f64::MAX, f64::min);
        let hi = xs.iter().cloned().fold(f64::MIN, f64::max);
        assert_eq!((lo, hi), (3.0, 7.0));
        // A block with a hole: two loops.
        f[3 * w + 4] = 1.0;
        f[3 * w + 5] = 1.0;
        assert_eq!(iso(&f, w, h, 0.5).len(), 2);
    }

    #[test]
    fn a_smooth_disc_is_traced_round_not_in_steps() {
        // A disc of radius 20 px with a soft (3 px) edge, as a blurred
        // picture has.
        let (w, h, r) = (60usize, 60usize, 20.0f64);
        let mut f = vec![1.0f32; w * h];
        for y in 0..h {
            for x in 0..w {
                let d = (x as f64 + 0.5 - 30.0).hypot(y as f64 + 0.5 - 30.0);
                f[y * w + x] = ((d - r) / 3.0 + 0.5).clamp(0.0, 1.0) as f32;
            }
        }
        let rings = iso(&f, w, h, 0.5);
        assert_eq!(rings.len(), 1);
        // Every point within a twentieth of a pixel of the circle …
        for p in &rings[0] {
            let d = (p[0] - 30.0).hypot(p[1] - 30.0);
            assert!((d - r).abs() < 0.05, "{p:?} at {d}");
        }
        // … and simplified to 0.1 px it keeps no staircase: no two
        // consecutive segments are both axis-parallel.
        let s = simplify(&rings[0], 0.1);
        let axis = |a: [f64; 2], b: [f64; 2]| a[0] == b[0] || a[1] == b[1];
        for k in 2..s.len() {
            assert!(
                !(axis(s[k - 2], s[k - 1]) && axis(s[k - 1], s[k])),
                "{:?}",
                &s[k - 2..=k]
            );
        }
    }
}
