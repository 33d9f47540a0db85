//! The order the pen draws its strokes in, to travel less with the pen up
//! (the plotting form of the travelling-salesman problem, as vpype's
//! `linesort`): greedy nearest neighbour — each stroke may be drawn either
//! way, a closed one from any of its points — then 2-opt, which reverses a
//! run of strokes (and each stroke in it) whenever that shortens the two
//! travels at its ends. The pen starts and ends at `home`. Never worse
//! than the order given: if it were, the order given is kept. Before
//! ordering, [`merge`] joins strokes that touch end to end (vpype's
//! `linemerge`), so the pen is not lifted where the line goes on.

use super::trace::Polyline;

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

fn closed(s: &Polyline) -> bool {
    s.len() > 2 && s.first() == s.last()
}

/// Strokes whose ends meet (within `tolerance`) joined into one, either
/// way round; a stroke that comes back to its start stays closed.
pub fn merge(strokes: Vec<Polyline>, tolerance: f64) -> Vec<Polyline> {
    use std::collections::HashMap;
    let cell = tolerance.max(1e-9);
    let key = |p: [f64; 2]| ((p[0] / cell).floor() as i64, (p[1] / cell).floor() as i64);
    // Ends by grid cell: (stroke, is its last point).
    let mut grid: HashMap<(i64, i64), Vec<(usize, bool)>> = HashMap::new();
    let strokes: Vec<Polyline> = strokes.into_iter().filter(|s| s.len() >= 2).collect();
    for (i, s) in strokes.iter().enumerate() {
        if !closed(s) {
            grid.entry(key(s[0])).or_default().push((i, false));
            grid.entry(key(*s.last().unwrap()))
                .or_default()
                .push((i, true));
        }
    }
    let mut used = vec![false; strokes.len()];
    // An unused open stroke with an end within reach of `p`.
    let find = |p: [f64; 2], used: &[bool]| {
        let (cx, cy) = key(p);
        let mut best: Option<(f64, usize, bool)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for &(i, last) in grid.get(&(cx + dx, cy + dy)).into_iter().flatten() {
                    let q = if last {
                        *strokes[i].last().unwrap()
                    } else {
                        strokes[i][0]
                    };
                    let d = dist(p, q);
                    if !used[i] && d <= tolerance && best.is_none_or(|b| d < b.0) {
                        best = Some((d, i, last));
                    }
                }
            }
        }
        best.map(|b| (b.1, b.2))
    };
    let mut out = Vec::new();
    for i in 0..strokes.len() {
        if used[i] {
            continue;
        }
        used[i] = true;
        let mut line = strokes[i].clone();
        if !closed(&line) {
            // Grow at the end, then at the start.
            for _ in 0..2 {
                while let Some((j, last)) = find(*line.last().unwrap(), &used) {
                    used[j] = true;
                    let mut more = strokes[j].clone();
                    if last {
                        more.reverse();
                    }
                    line.extend_from_slice(&more[1..]);
                }
                line.reverse();
            }
        }
        out.push(line);
    }
    out
}

/// Pen-up travel of drawing `strokes` in this order, from `home` and back.
pub fn pen_up_mm(strokes: &[Polyline], home: [f64; 2]) -> f64 {
    let mut at = home;
    let mut total = 0.0;
    for s in strokes.iter().filter(|s| !s.is_empty()) {
        total += dist(at, s[0]);
        at = *s.last().unwrap();
    }
    total + dist(at, home)
}

/// The strokes reordered (and some reversed, or started elsewhere when
/// closed) for less pen-up travel.
pub fn order(strokes: Vec<Polyline>, home: [f64; 2]) -> Vec<Polyline> {
    let before = pen_up_mm(&strokes, home);
    let mut path = nearest_neighbour(&strokes, home);
    two_opt(&mut path, home);
    match pen_up_mm(&path, home) <= before {
        true => path,
        false => strokes,
    }
}

fn nearest_neighbour(strokes: &[Polyline], home: [f64; 2]) -> Vec<Polyline> {
    // Every place a stroke may start: (stroke, vertex, reversed).
    let mut entries: Vec<(usize, usize, bool, [f64; 2])> = Vec::new();
    for (k, s) in strokes.iter().enumerate().filter(|(_, s)| !s.is_empty()) {
        if closed(s) {
            entries.extend((0..s.len() - 1).map(|v| (k, v, false, s[v])));
        } else {
            entries.push((k, 0, false, s[0]));
            entries.push((k, s.len() - 1, true, s[s.len() - 1]));
        }
    }
    let mut done = vec![false; strokes.len()];
    let mut out = Vec::with_capacity(strokes.len());
    let mut at = home;
    loop {
        let best = entries
            .iter()
            .filter(|e| !done[e.0])
            .map(|e| (dist(at, e.3), e))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        let Some((_, &(k, v, reversed, _))) = best else {
            break;
        };
        done[k] = true;
        let s = &strokes[k];
        let drawn: Polyline = if closed(s) {
            // From vertex v round to v again.
            s[v..s.len() - 1].iter().chain(&s[..=v]).copied().collect()
        } else if reversed {
            s.iter().rev().copied().collect()
        } else {
            s.clone()
        };
        at = *drawn.last().unwrap();
        out.push(drawn);
    }
    out
}

/// 2-opt over the strokes' ends, first improvement, until no move gains or
/// a bounded amount of work is done (so the result does not depend on the
/// machine's speed).
fn two_opt(path: &mut [Polyline], home: [f64; 2]) {
    let n = path.len();
    if n < 3 {
        return;
    }
    let start = |p: &[Polyline], i: usize| if i == n { home } else { p[i][0] };
    let end = |p: &[Polyline], i: Option<usize>| i.map_or(home, |i| *p[i].last().unwrap());
    let mut budget: u64 = 200_000_000;
    let mut improved = true;
    while improved && budget > 0 {
        improved = false;
        // Reverse strokes i..=j: travels (i−1 → i) and (j → j+1) change.
        for i in 0..n {
            for j in i + 1..n {
                budget = budget.saturating_sub(1);
                let (before, after) = (end(path, i.checked_sub(1)), start(path, j + 1));
                let old = dist(before, path[i][0]) + dist(*path[j].last().unwrap(), after);
                let new = dist(before, *path[j].last().unwrap()) + dist(path[i][0], after);
                if new < old - 1e-9 {
                    path[i..=j].reverse();
                    for s in &mut path[i..=j] {
                        s.reverse();
                    }
                    improved = true;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stringart::greedy::Rng;

    fn random_strokes(rng: &mut Rng, n: usize) -> Vec<Polyline> {
        let mut r = || rng.below(10_000) as f64 / 100.0;
        (0..n)
            .map(|k| match k % 3 {
                // A closed square, or an open two- or three-point stroke.
                0 => {
                    let (x, y) = (r(), r());
                    vec![
                        [x, y],
                        [x + 2.0, y],
                        [x + 2.0, y + 2.0],
                        [x, y + 2.0],
                        [x, y],
                    ]
                }
                1 => vec![[r(), r()], [r(), r()]],
                _ => vec![[r(), r()], [r(), r()], [r(), r()]],
            })
            .collect()
    }

    /// Every stroke drawn once, the same points, either way round.
    fn same_strokes(a: &[Polyline], b: &[Polyline]) -> bool {
        let key = |s: &Polyline| {
            let mut pts: Vec<(i64, i64)> = s
                .iter()
                .map(|p| ((p[0] * 1e6) as i64, (p[1] * 1e6) as i64))
                .collect();
            if closed(s) {
                pts.pop();
            }
            pts.sort_unstable();
            pts
        };
        let mut x: Vec<_> = a.iter().map(key).collect();
        let mut y: Vec<_> = b.iter().map(key).collect();
        x.sort();
        y.sort();
        x == y
    }

    #[test]
    fn ordering_never_adds_travel_and_keeps_every_stroke() {
        let mut rng = Rng::new(11);
        for trial in 0..40 {
            let strokes = random_strokes(&mut rng, 1 + trial * 7);
            let before = pen_up_mm(&strokes, [0.0; 2]);
            let ordered = order(strokes.clone(), [0.0; 2]);
            let after = pen_up_mm(&ordered, [0.0; 2]);
            assert!(after <= before + 1e-9, "trial {trial}: {after} > {before}");
            assert!(same_strokes(&strokes, &ordered), "trial {trial}");
            if trial > 5 {
                assert!(
                    after < 0.6 * before,
                    "trial {trial}: only {before} → {after}"
                );
            }
        }
    }

    #[test]
    fn touching_strokes_merge_either_way_round() {
        let strokes = vec![
            vec![[0.0, 0.0], [1.0, 0.0]],
            vec![[2.0, 0.0], [1.0, 0.0]],
            vec![[2.0, 0.0], [3.0, 1.0]],
            vec![[10.0, 0.0], [11.0, 0.0]],
            vec![[5.0, 5.0], [6.0, 5.0], [6.0, 6.0], [5.0, 5.0]],
        ];
        let m = merge(strokes, 0.01);
        assert_eq!(m.len(), 3, "{m:?}");
        let long = m.iter().find(|s| s.len() == 4).unwrap();
        let ends = [long[0], long[3]];
        assert!(
            ends.contains(&[0.0, 0.0]) && ends.contains(&[3.0, 1.0]),
            "{long:?}"
        );
        // Within the tolerance only.
        assert_eq!(
            merge(
                vec![vec![[0.0, 0.0], [1.0, 0.0]], vec![[1.1, 0.0], [2.0, 0.0]]],
                0.05
            )
            .len(),
            2
        );
    }

    #[test]
    fn a_row_of_dashes_is_drawn_left_to_right_in_turn() {
        // Given right to left, each pointing left.
        let strokes: Vec<Polyline> = (0..5)
            .rev()
            .map(|k| vec![[k as f64 * 10.0 + 5.0, 0.0], [k as f64 * 10.0, 0.0]])
            .collect();
        let ordered = order(strokes, [0.0; 2]);
        let starts: Vec<f64> = ordered.iter().map(|s| s[0][0]).collect();
        assert_eq!(starts, [0.0, 10.0, 20.0, 30.0, 40.0]);
        assert_eq!(pen_up_mm(&ordered, [0.0; 2]), 4.0 * 5.0 + 45.0);
    }
}
