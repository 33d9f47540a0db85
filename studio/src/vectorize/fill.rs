//! Regions filled with parallel lines: the scan lines `spacing` apart at
//! `angle` degrees (counter-clockwise from +x, in the frame of the rings)
//! clipped to the inside of closed rings, exactly (each line's crossings
//! with the rings' edges, inside by the even-odd or non-zero rule, as SVG
//! fills). Works in any unit; the rings are closed polylines.

use super::trace::Polyline;

/// SVG's `fill-rule`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rule {
    EvenOdd,
    NonZero,
}

/// The hatch lines inside `rings`: offsets `(k + phase) · spacing` across
/// the lines, for whole k. Each inside run is one two-point stroke.
pub fn hatch(
    rings: &[Polyline],
    rule: Rule,
    spacing: f64,
    angle: f64,
    phase: f64,
) -> Vec<Polyline> {
    let a = angle.to_radians();
    // Along the lines, and across them.
    let (u, n) = ([a.cos(), a.sin()], [-a.sin(), a.cos()]);
    let dot = |p: [f64; 2], d: [f64; 2]| p[0] * d[0] + p[1] * d[1];
    let edges = rings.iter().flat_map(|r| {
        let closing = match (r.first(), r.last()) {
            (Some(f), Some(l)) if f != l => Some([*l, *f]),
            _ => None,
        };
        r.windows(2).map(|w| [w[0], w[1]]).chain(closing)
    });
    let line_of = |o: f64| ((o / spacing) - phase).ceil() as i64;
    // Each scan line's crossings: (position along the line, ±1 winding).
    let mut cuts: std::collections::BTreeMap<i64, Vec<(f64, i32)>> = Default::default();
    for [p, q] in edges {
        let (op, oq) = (dot(p, n), dot(q, n));
        if op == oq {
            continue;
        }
        let (lo, hi, dir) = match op < oq {
            true => (op, oq, 1),
            false => (oq, op, -1),
        };
        // Lines at offsets in [lo, hi): each crossing counted once where
        // two edges meet.
        for k in line_of(lo)..line_of(hi) {
            let o = (k as f64 + phase) * spacing;
            if o < lo || o >= hi {
                continue;
            }
            let t = (o - op) / (oq - op);
            let along = dot(p, u) + t * (dot(q, u) - dot(p, u));
            cuts.entry(k).or_default().push((along, dir));
        }
    }
    let mut out = Vec::new();
    for (k, mut c) in cuts {
        let o = (k as f64 + phase) * spacing;
        c.sort_by(|a, b| a.0.total_cmp(&b.0));
        let point = |t: f64| [u[0] * t + n[0] * o, u[1] * t + n[1] * o];
        let mut winding = 0;
        for w in c.windows(2) {
            winding += w[0].1;
            let inside = match rule {
                Rule::EvenOdd => winding % 2 != 0,
                Rule::NonZero => winding != 0,
            };
            if inside && w[1].0 - w[0].0 > 1e-9 {
                out.push(vec![point(w[0].0), point(w[1].0)]);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x: f64, y: f64, side: f64, ccw: bool) -> Polyline {
        let mut s = vec![
            [x, y],
            [x + side, y],
            [x + side, y + side],
            [x, y + side],
            [x, y],
        ];
        if !ccw {
            s.reverse();
        }
        s
    }

    #[test]
    fn a_square_gets_evenly_spaced_lines_edge_to_edge() {
        let lines = hatch(
            &[square(10.0, 5.0, 10.0, true)],
            Rule::EvenOdd,
            2.0,
            0.0,
            0.5,
        );
        let ys: Vec<f64> = lines.iter().map(|l| l[0][1]).collect();
        assert_eq!(ys, [5.0, 7.0, 9.0, 11.0, 13.0]);
        for l in &lines {
            assert_eq!((l[0][0], l[1][0]), (10.0, 20.0));
        }
        // At 45°: every line's ends on the square's edges, its length the
        // chord there.
        let l = hatch(
            &[square(0.0, 0.0, 10.0, true)],
            Rule::EvenOdd,
            1.0,
            45.0,
            0.0,
        );
        let total: f64 = l
            .iter()
            .map(|l| (l[1][0] - l[0][0]).hypot(l[1][1] - l[0][1]))
            .sum();
        // Area / spacing.
        assert!((total - 100.0).abs() < 1.5, "{total}");
        for p in l.iter().flatten() {
            assert!(p[0] > -1e-9 && p[0] < 10.0 + 1e-9 && p[1] > -1e-9 && p[1] < 10.0 + 1e-9);
        }
    }

    #[test]
    fn holes_follow_the_fill_rule() {
        // An outer square and an inner one: even-odd leaves the hole; the
        // non-zero rule leaves it only when the inner one turns the other
        // way.
        let outer = square(0.0, 0.0, 30.0, true);
        let len = |l: &[Polyline]| l.iter().map(|l| (l[1][0] - l[0][0]).abs()).sum::<f64>();
        let same = [outer.clone(), square(10.0, 10.0, 10.0, true)];
        let other = [outer.clone(), square(10.0, 10.0, 10.0, false)];
        let full = len(&hatch(&[outer], Rule::EvenOdd, 1.0, 0.0, 0.5));
        assert_eq!(full, 900.0);
        assert_eq!(len(&hatch(&same, Rule::EvenOdd, 1.0, 0.0, 0.5)), 800.0);
        assert_eq!(len(&hatch(&same, Rule::NonZero, 1.0, 0.0, 0.5)), 900.0);
        assert_eq!(len(&hatch(&other, Rule::NonZero, 1.0, 0.0, 0.5)), 800.0);
    }
}
