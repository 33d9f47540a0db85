//! Point reduction within a tolerance (Ramer–Douglas–Peucker): the fewest
//! points such that every dropped point lies within `tolerance` of the
//! segment that replaces it.

use super::trace::Polyline;

pub fn simplify(line: &[[f64; 2]], tolerance: f64) -> Polyline {
    if line.len() <= 2 {
        return line.to_vec();
    }
    let mut keep = vec![false; line.len()];
    keep[0] = true;
    keep[line.len() - 1] = true;
    let mut spans = vec![(0, line.len() - 1)];
    while let Some((a, b)) = spans.pop() {
        let (far, d) = (a + 1..b)
            .map(|i| (i, distance(line[i], line[a], line[b])))
            .fold((a, 0.0), |best, c| if c.1 > best.1 { c } else { best });
        if d > tolerance {
            keep[far] = true;
            spans.push((a, far));
            spans.push((far, b));
        }
    }
    line.iter()
        .zip(keep)
        .filter(|(_, k)| *k)
        .map(|(p, _)| *p)
        .collect()
}

/// Distance from `p` to the segment `a`–`b`.
pub fn distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = match len2 > 0.0 {
        true => (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0),
        false => 0.0,
    };
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_runs_shrink_to_their_ends_and_every_point_stays_close() {
        let line: Vec<[f64; 2]> = (0..50).map(|i| [i as f64, 0.0]).collect();
        assert_eq!(simplify(&line, 0.1), [[0.0, 0.0], [49.0, 0.0]]);
        // A staircase within half a pixel of a diagonal.
        let stairs: Vec<[f64; 2]> = (0..40)
            .map(|i| [(i / 2 + i % 2) as f64, (i / 2) as f64])
            .collect();
        let s = simplify(&stairs, 0.75);
        assert!(s.len() <= 3, "{s:?}");
        for p in &stairs {
            let d = s
                .windows(2)
                .map(|w| distance(*p, w[0], w[1]))
                .fold(f64::MAX, f64::min);
            assert!(d <= 0.75 + 1e-12);
        }
        // A corner stays.
        let corner = [
            [0.0, 0.0],
            [5.0, 0.0],
            [10.0, 0.0],
            [10.0, 5.0],
            [10.0, 10.0],
        ];
        assert_eq!(
            simplify(&corner, 0.5),
            [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]]
        );
    }
}
