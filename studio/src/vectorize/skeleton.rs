//! Centre-lines of line art: each drawn line becomes one pen stroke along
//! its middle, as potrace's and autotrace's centre-line modes do, instead
//! of two outlines round it.
//!
//! The dark pixels are thinned to a one-pixel skeleton (Zhang–Suen); the
//! skeleton is cut into curves between its ends and junctions (a cluster
//! of touching junction pixels is one junction); spurs shorter than the
//! line's width (thinning's whiskers at corners) are dropped; at each
//! junction the curves that continue each other most nearly straight are
//! joined, so a crossing is two strokes, not four; free ends are extended
//! by the line's half width, which thinning ate; each curve is smoothed
//! (its pixel staircase averaged out) and left for the caller to
//! simplify. Every skeleton pixel lies on exactly one curve: no line is
//! drawn twice.

use super::trace::Polyline;
use std::collections::HashMap;

const NEIGHBOURS: [(isize, isize); 8] = [
    (0, -1),
    (1, -1),
    (1, 0),
    (1, 1),
    (0, 1),
    (-1, 1),
    (-1, 0),
    (-1, -1),
];

/// The centre-lines of the pixels where `dark` holds, in pixel
/// coordinates (centres at + 0.5), with each line's width in pixels.
pub fn centre_lines(dark: &[bool], w: usize, h: usize) -> Vec<Polyline> {
    let depth = distance(dark, w, h);
    let skel = thin(dark, w, h);
    let graph = Graph::new(&skel, w, h);
    let mut curves = graph.curves();
    prune(&mut curves, &graph, &depth, w);
    let strokes = join(curves, &graph, w);
    strokes
        .into_iter()
        .map(|s| finish(&s, &graph, &depth, w))
        .filter(|s| s.len() >= 2)
        .collect()
}

/// Distance of each dark pixel to the nearest light one, pixels (a 3–4
/// chamfer, within 8 %); 0 on light pixels.
pub fn distance(dark: &[bool], w: usize, h: usize) -> Vec<f32> {
    let big = f32::MAX / 4.0;
    let mut d: Vec<f32> = dark.iter().map(|&k| if k { big } else { 0.0 }).collect();
    let at = |x: isize, y: isize, d: &[f32]| match x >= 0
        && y >= 0
        && (x as usize) < w
        && (y as usize) < h
    {
        true => d[y as usize * w + x as usize],
        false => 0.0,
    };
    for y in 0..h as isize {
        for x in 0..w as isize {
            let i = y as usize * w + x as usize;
            if d[i] > 0.0 {
                let m = (at(x - 1, y, &d) + 1.0)
                    .min(at(x, y - 1, &d) + 1.0)
                    .min(at(x - 1, y - 1, &d) + 1.4)
                    .min(at(x + 1, y - 1, &d) + 1.4);
                d[i] = d[i].min(m);
            }
        }
    }
    for y in (0..h as isize).rev() {
        for x in (0..w as isize).rev() {
            let i = y as usize * w + x as usize;
            if d[i] > 0.0 {
                let m = (at(x + 1, y, &d) + 1.0)
                    .min(at(x, y + 1, &d) + 1.0)
                    .min(at(x + 1, y + 1, &d) + 1.4)
                    .min(at(x - 1, y + 1, &d) + 1.4);
                d[i] = d[i].min(m);
            }
        }
    }
    d
}

/// Zhang–Suen thinning: the dark pixels peeled from outside in, keeping
/// their connections, to lines one pixel thick.
pub fn thin(dark: &[bool], w: usize, h: usize) -> Vec<bool> {
    let mut img = dark.to_vec();
    let get = |img: &[bool], x: isize, y: isize| {
        x >= 0 && y >= 0 && (x as usize) < w && (y as usize) < h && img[y as usize * w + x as usize]
    };
    let mut candidates: Vec<usize> = (0..w * h).filter(|&i| img[i]).collect();
    loop {
        let mut changed = false;
        for pass in 0..2 {
            let mut remove = Vec::new();
            for &i in &candidates {
                if !img[i] {
                    continue;
                }
                let (x, y) = ((i % w) as isize, (i / w) as isize);
                let p: Vec<bool> = NEIGHBOURS
                    .iter()
                    .map(|&(dx, dy)| get(&img, x + dx, y + dy))
                    .collect();
                let b = p.iter().filter(|&&v| v).count();
                let a = (0..8).filter(|&k| !p[k] && p[(k + 1) % 8]).count();
                // p[0] north, p[2] east, p[4] south, p[6] west.
                let (c1, c2) = match pass {
                    0 => (p[0] && p[2] && p[4], p[2] && p[4] && p[6]),
                    _ => (p[0] && p[2] && p[6], p[0] && p[4] && p[6]),
                };
                if (2..=6).contains(&b) && a == 1 && !c1 && !c2 {
                    remove.push(i);
                }
            }
            changed |= !remove.is_empty();
            for i in remove {
                img[i] = false;
            }
        }
        if !changed {
            return img;
        }
        candidates.retain(|&i| img[i]);
    }
}

/// The skeleton as a graph: its pixels, each pixel's skeleton neighbours,
/// and the nodes (ends, and junctions with touching junction pixels
/// merged).
struct Graph {
    w: usize,
    on: Vec<bool>,
    /// For node pixels: their node's index.
    node_of: HashMap<usize, usize>,
    /// Each node's pixels.
    nodes: Vec<Vec<usize>>,
}

/// A curve of skeleton pixels and the nodes at its ends (`None`: a loop
/// with no node).
#[derive(Clone, Debug)]
struct Curve {
    pixels: Vec<usize>,
    ends: [Option<usize>; 2],
}

impl Graph {
    fn new(on: &[bool], w: usize, h: usize) -> Graph {
        let mut g = Graph {
            w,
            on: on.to_vec(),
            node_of: HashMap::new(),
            nodes: Vec::new(),
        };
        let _ = h;
        let is_node: Vec<usize> = (0..on.len())
            .filter(|&i| on[i] && g.neighbours(i).count() != 2)
            .collect();
        // Touching junction pixels form one node.
        for &i in &is_node {
            if g.node_of.contains_key(&i) {
                continue;
            }
            let k = g.nodes.len();
            let mut members = vec![i];
            g.node_of.insert(i, k);
            let mut at = 0;
            while at < members.len() {
                let p = members[at];
                at += 1;
                let more: Vec<usize> = g
                    .neighbours(p)
                    .filter(|q| {
                        !g.node_of.contains_key(q)
                            && g.neighbours(*q).count() > 2
                            && g.neighbours(p).count() > 2
                    })
                    .collect();
                for q in more {
                    g.node_of.insert(q, k);
                    members.push(q);
                }
            }
            g.nodes.push(members);
        }
        g
    }

    fn neighbours(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        let (x, y) = ((i % self.w) as isize, (i / self.w) as isize);
        let h = self.on.len() / self.w;
        NEIGHBOURS.iter().filter_map(move |&(dx, dy)| {
            let (nx, ny) = (x + dx, y + dy);
            let inside = nx >= 0 && ny >= 0 && (nx as usize) < self.w && (ny as usize) < h;
            let j = ny as usize * self.w + nx as usize;
            (inside && self.on[j]).then_some(j)
        })
    }

    fn centre(&self, i: usize) -> [f64; 2] {
        [(i % self.w) as f64 + 0.5, (i / self.w) as f64 + 0.5]
    }

    /// A node's place: the mean of its pixels.
    fn node_point(&self, k: usize) -> [f64; 2] {
        let n = self.nodes[k].len() as f64;
        let s = self.nodes[k].iter().fold([0.0, 0.0], |s, &i| {
            let c = self.centre(i);
            [s[0] + c[0], s[1] + c[1]]
        });
        [s[0] / n, s[1] / n]
    }

    /// Every curve: from each node along each way out to the next node,
    /// then the loops that have no node. Each pixel on one curve.
    fn curves(&self) -> Vec<Curve> {
        let mut used = vec![false; self.on.len()];
        let mut out = Vec::new();
        for (k, members) in self.nodes.iter().enumerate() {
            for &m in members {
                used[m] = true;
            }
            for &m in members {
                let starts: Vec<usize> = self
                    .neighbours(m)
                    .filter(|q| !self.node_of.contains_key(q))
                    .collect();
                for s in starts {
                    if used[s] {
                        continue;
                    }
                    let mut pixels = vec![s];
                    used[s] = true;
                    let mut at = s;
                    let mut end = None;
                    loop {
                        // A node next to the walk ends it (not the node we
                        // started from on the first step).
                        let node = self
                            .neighbours(at)
                            .filter_map(|q| self.node_of.get(&q).copied())
                            .find(|&n| n != k || pixels.len() > 1);
                        if let Some(n) = node {
                            end = Some(n);
                            break;
                        }
                        match self
                            .neighbours(at)
                            .find(|&q| !used[q] && !self.node_of.contains_key(&q))
                        {
                            Some(q) => {
                                used[q] = true;
                                pixels.push(q);
                                at = q;
                            }
                            None => break,
                        }
                    }
                    out.push(Curve {
                        pixels,
                        ends: [Some(k), end],
                    });
                }
                // A single-pixel skeleton (a dot) or two touching nodes.
            }
            // An isolated node pixel with no curve: a dot.
            if members.len() == 1 && self.neighbours(members[0]).count() == 0 {
                out.push(Curve {
                    pixels: vec![members[0]],
                    ends: [Some(k), None],
                });
            }
        }
        // Two nodes side by side (a two-pixel line, a short bridge).
        for (k, members) in self.nodes.iter().enumerate() {
            for &m in members {
                for q in self.neighbours(m) {
                    if let Some(&n) = self.node_of.get(&q) {
                        if n > k
                            && !out
                                .iter()
                                .any(|c| c.pixels.is_empty() && c.ends == [Some(k), Some(n)])
                        {
                            out.push(Curve {
                                pixels: Vec::new(),
                                ends: [Some(k), Some(n)],
                            });
                        }
                    }
                }
            }
        }
        for i in 0..self.on.len() {
            if self.on[i] && !used[i] {
                let mut pixels = vec![i];
                used[i] = true;
                let mut at = i;
                while let Some(q) = self.neighbours(at).find(|&q| !used[q]) {
                    used[q] = true;
                    pixels.push(q);
                    at = q;
                }
                pixels.push(i);
                out.push(Curve {
                    pixels,
                    ends: [None, None],
                });
            }
        }
        out
    }

    /// How many curves meet at node `k`.
    fn degree(curves: &[Curve], k: usize) -> usize {
        curves
            .iter()
            .map(|c| c.ends.iter().filter(|&&e| e == Some(k)).count())
            .sum()
    }
}

/// Drops spurs: a curve from a junction to a free end shorter than the
/// line's width there.
fn prune(curves: &mut Vec<Curve>, g: &Graph, depth: &[f32], w: usize) {
    let _ = w;
    loop {
        let spur = curves.iter().position(|c| {
            let [Some(a), b] = c.ends else { return false };
            let free_end = match b {
                Some(b) => Graph::degree(curves, b) == 1,
                None => false,
            };
            let width = 2.0 * g.nodes[a].iter().map(|&i| depth[i]).fold(0.0f32, f32::max);
            free_end && Graph::degree(curves, a) >= 3 && (c.pixels.len() as f32) < width
        });
        match spur {
            Some(i) => {
                curves.remove(i);
            }
            None => return,
        }
    }
}

/// A curve's direction leaving node `k`: from the node towards a point a
/// few pixels along it.
fn leaving(c: &Curve, k: usize, g: &Graph) -> [f64; 2] {
    let from = g.node_point(k);
    let px: Vec<usize> = match c.ends[0] == Some(k) {
        true => c.pixels.clone(),
        false => c.pixels.iter().rev().copied().collect(),
    };
    let to = match px.get(6.min(px.len().saturating_sub(1))) {
        Some(&i) => g.centre(i),
        None => {
            let other = if c.ends[0] == Some(k) {
                c.ends[1]
            } else {
                c.ends[0]
            };
            other.map_or(from, |o| g.node_point(o))
        }
    };
    let d = [to[0] - from[0], to[1] - from[1]];
    let n = d[0].hypot(d[1]).max(1e-9);
    [d[0] / n, d[1] / n]
}

/// Joins curves through junctions: at each node, the two curves that
/// continue each other most nearly straight (within 50°) become one,
/// repeatedly. The result: point lists through the nodes' centres.
fn join(curves: Vec<Curve>, g: &Graph, w: usize) -> Vec<Vec<Piece>> {
    let _ = w;
    // Pairs (curve end) ↔ (curve end) at nodes.
    let n = curves.len();
    let mut partner: HashMap<(usize, usize), (usize, usize)> = HashMap::new();
    for k in 0..g.nodes.len() {
        let mut ends: Vec<(usize, usize, [f64; 2])> = Vec::new();
        for (ci, c) in curves.iter().enumerate() {
            for side in 0..2 {
                if c.ends[side] == Some(k)
                    && !(c.ends[0] == c.ends[1] && side == 1 && c.pixels.is_empty())
                {
                    ends.push((ci, side, leaving(c, k, g)));
                }
            }
        }
        if ends.len() < 2 {
            continue;
        }
        let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
        for a in 0..ends.len() {
            for b in a + 1..ends.len() {
                let (da, db) = (ends[a].2, ends[b].2);
                // Straight on: the directions opposite, cosine −1.
                let cos = da[0] * db[0] + da[1] * db[1];
                if cos < -(40f64.to_radians().cos()) || ends.len() == 2 {
                    pairs.push((cos, a, b));
                }
            }
        }
        pairs.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut taken = vec![false; ends.len()];
        for (_, a, b) in pairs {
            if taken[a] || taken[b] || (ends[a].0 == ends[b].0 && ends[a].1 == ends[b].1) {
                continue;
            }
            taken[a] = true;
            taken[b] = true;
            let (ea, eb) = ((ends[a].0, ends[a].1), (ends[b].0, ends[b].1));
            partner.insert(ea, eb);
            partner.insert(eb, ea);
        }
    }
    // Walk chains of curves through their partners.
    let mut used = vec![false; n];
    let mut out = Vec::new();
    let walk = |start: usize, from_side: usize, used: &mut Vec<bool>| {
        let mut chain = Vec::new();
        let (mut ci, mut side) = (start, from_side);
        loop {
            used[ci] = true;
            chain.push(Piece {
                curve: curves[ci].clone(),
                forward: side == 0,
            });
            let exit = (ci, 1 - side);
            match partner.get(&exit) {
                Some(&(next, next_side)) if !used[next] => {
                    ci = next;
                    side = next_side;
                }
                _ => break,
            }
        }
        chain
    };
    // Chains start at an end with no partner; what is left are rings.
    for ci in 0..n {
        for side in 0..2 {
            if !used[ci] && !partner.contains_key(&(ci, side)) {
                out.push(walk(ci, side, &mut used));
            }
        }
    }
    for ci in 0..n {
        if !used[ci] {
            out.push(walk(ci, 0, &mut used));
        }
    }
    out
}

/// One curve in a stroke, and which way it is walked.
struct Piece {
    curve: Curve,
    forward: bool,
}

/// A stroke's points: through node centres, ends extended by the half
/// width thinning ate, smoothed.
fn finish(pieces: &[Piece], g: &Graph, depth: &[f32], w: usize) -> Polyline {
    let _ = w;
    let mut pts: Vec<[f64; 2]> = Vec::new();
    for p in pieces {
        let c = &p.curve;
        let (first, last) = match p.forward {
            true => (c.ends[0], c.ends[1]),
            false => (c.ends[1], c.ends[0]),
        };
        let px: Vec<usize> = match p.forward {
            true => c.pixels.clone(),
            false => c.pixels.iter().rev().copied().collect(),
        };
        let mut add = |q: [f64; 2]| {
            if pts.last() != Some(&q) {
                pts.push(q);
            }
        };
        if let Some(k) = first {
            add(g.node_point(k));
        }
        for &i in &px {
            add(g.centre(i));
        }
        if let Some(k) = last {
            add(g.node_point(k));
        }
    }
    let closed = pts.len() > 2 && pts.first() == pts.last();
    let mut pts = smooth(&pts, closed);
    // Free ends (a node with one curve, or a curve's pixel end) reach
    // out by the line's half width.
    let free = |node: Option<usize>| {
        node.is_none_or(|k| g.nodes[k].len() == 1 && g.neighbours(g.nodes[k][0]).count() <= 1)
    };
    if !closed && pts.len() >= 2 {
        let first = &pieces[0];
        let last = &pieces[pieces.len() - 1];
        let start_node = if first.forward {
            first.curve.ends[0]
        } else {
            first.curve.ends[1]
        };
        let end_node = if last.forward {
            last.curve.ends[1]
        } else {
            last.curve.ends[0]
        };
        let reach = |p: [f64; 2]| {
            let i = (p[1] as usize).min(depth.len() / g.w - 1) * g.w + (p[0] as usize).min(g.w - 1);
            (f64::from(depth[i]) - 0.5).max(0.0)
        };
        if free(start_node) {
            let (a, b) = (
                pts[0],
                pts[1.min(pts.len() - 1)..]
                    .iter()
                    .find(|q| **q != pts[0])
                    .copied()
                    .unwrap_or(pts[0]),
            );
            pts[0] = extend(a, b, reach(a));
        }
        let n = pts.len();
        if free(end_node) {
            let a = pts[n - 1];
            let b = pts[..n - 1]
                .iter()
                .rev()
                .find(|q| **q != a)
                .copied()
                .unwrap_or(a);
            pts[n - 1] = extend(a, b, reach(a));
        }
    }
    pts
}

/// `a` moved `by` away from `b`.
fn extend(a: [f64; 2], b: [f64; 2], by: f64) -> [f64; 2] {
    let d = [a[0] - b[0], a[1] - b[1]];
    let n = d[0].hypot(d[1]);
    match n > 1e-9 {
        true => [a[0] + d[0] / n * by, a[1] + d[1] / n * by],
        false => a,
    }
}

/// Two passes of a three-point mean, the ends kept (a closed ring wraps).
fn smooth(pts: &[[f64; 2]], closed: bool) -> Polyline {
    let mut p = pts.to_vec();
    let n = p.len();
    if n < 3 {
        return p;
    }
    for _ in 0..2 {
        let q = p.clone();
        for i in 0..n {
            let (a, b) = match (i, closed) {
                (0, false) => continue,
                (i, false) if i == n - 1 => continue,
                (0, true) => (q[n - 2], q[1]),
                (i, true) if i == n - 1 => (q[n - 2], q[1]),
                (i, _) => (q[i - 1], q[i + 1]),
            };
            p[i] = [
                (a[0] + 2.0 * q[i][0] + b[0]) / 4.0,
                (a[1] + 2.0 * q[i][1] + b[1]) / 4.0,
            ];
        }
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    fn disc_brush(dark: &mut [bool], w: usize, a: [f64; 2], b: [f64; 2], r: f64) {
        let h = dark.len() / w;
        for y in 0..h {
            for x in 0..w {
                let p = [x as f64 + 0.5, y as f64 + 0.5];
                if crate::vectorize::simplify::distance(p, a, b) <= r {
                    dark[y * w + x] = true;
                }
            }
        }
    }

    fn length(s: &Polyline) -> f64 {
        s.windows(2)
            .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
            .sum()
    }

    #[test]
    fn a_thick_line_is_one_stroke_its_length() {
        let (w, h) = (120, 40);
        let mut d = vec![false; w * h];
        disc_brush(&mut d, w, [10.0, 20.0], [110.0, 20.0], 3.0);
        let s = centre_lines(&d, w, h);
        assert_eq!(s.len(), 1, "{s:?}");
        let l = length(&s[0]);
        // 100 px between the centres of the brush's ends, plus the round
        // caps thinning leaves (up to its radius each side).
        assert!((98.0..=108.0).contains(&l), "{l}");
        for p in &s[0] {
            assert!((p[1] - 20.0).abs() < 1.0, "{p:?}");
        }
    }

    #[test]
    fn a_cross_is_two_strokes_and_a_ring_one() {
        let (w, h) = (100, 100);
        let mut d = vec![false; w * h];
        disc_brush(&mut d, w, [10.0, 50.0], [90.0, 50.0], 2.5);
        disc_brush(&mut d, w, [50.0, 10.0], [50.0, 90.0], 2.5);
        let s = centre_lines(&d, w, h);
        assert_eq!(
            s.len(),
            2,
            "{:?}",
            s.iter().map(|s| (s[0], s[s.len() - 1])).collect::<Vec<_>>()
        );
        let total: f64 = s.iter().map(length).sum();
        assert!((155.0..=170.0).contains(&total), "{total}");
        let mut ring = vec![false; w * h];
        for k in 0..200 {
            let a = k as f64 / 200.0 * std::f64::consts::TAU;
            let b = (k + 1) as f64 / 200.0 * std::f64::consts::TAU;
            disc_brush(
                &mut ring,
                w,
                [50.0 + 30.0 * a.cos(), 50.0 + 30.0 * a.sin()],
                [50.0 + 30.0 * b.cos(), 50.0 + 30.0 * b.sin()],
                2.0,
            );
        }
        let s = centre_lines(&ring, w, h);
        assert_eq!(s.len(), 1);
        let l = length(&s[0]);
        assert!((l - 60.0 * std::f64::consts::PI).abs() < 0.05 * l, "{l}");
    }
}
