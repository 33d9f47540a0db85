//! From pixels to polylines (pixel coordinates, x right, y down):
//!
//! - [`chains`]: a one-pixel-thin edge map followed pixel to pixel, so each
//!   edge is drawn once (a border follower such as OpenCV's Suzuki–Abe
//!   `findContours` would go round a thin edge on both sides: twice the
//!   ink). Open chains start at their ends or junctions; what is left are
//!   closed loops.
//! - [`outlines`]: the boundaries of a dark region (marching squares at the
//!   threshold, between pixel centres), closed, for hatching.

use super::canny::NEIGHBOURS;

pub type Polyline = Vec<[f64; 2]>;

/// The edge map's pixel chains, through the pixels' centres.
pub fn chains(edge: &[bool], w: usize, h: usize) -> Vec<Polyline> {
    let neighbours = |i: usize| {
        let (x, y) = ((i % w) as isize, (i / w) as isize);
        NEIGHBOURS.into_iter().filter_map(move |(dx, dy)| {
            let (nx, ny) = (x + dx, y + dy);
            let inside = nx >= 0 && ny >= 0 && nx < w as isize && ny < h as isize;
            inside.then(|| ny as usize * w + nx as usize)
        })
    };
    let degree = |i: usize| neighbours(i).filter(|&j| edge[j]).count();
    let mut used = vec![false; edge.len()];
    let mut out = Vec::new();
    let centre = |i: usize| [(i % w) as f64 + 0.5, (i / w) as f64 + 0.5];
    let follow = |start: usize, used: &mut Vec<bool>| {
        let mut chain = vec![centre(start)];
        used[start] = true;
        let mut at = start;
        // Sides before diagonals: a staircase is walked step by step.
        while let Some(next) = neighbours(at).find(|&j| edge[j] && !used[j]) {
            used[next] = true;
            chain.push(centre(next));
            at = next;
        }
        // A loop comes back next to where it began: close it.
        if chain.len() > 3 && neighbours(at).any(|j| j == start) {
            chain.push(centre(start));
        }
        chain
    };
    // Ends and junctions first, then whatever is left (loops).
    for pass in 0..2 {
        for i in 0..edge.len() {
            if edge[i] && !used[i] && (pass == 1 || degree(i) != 2) {
                out.push(follow(i, &mut used));
            }
        }
    }
    out
}

/// The closed boundaries of the pixels where `dark` holds, by marching
/// squares over the pixel centres (the raster padded with light all
/// round, so every boundary closes).
pub fn outlines(dark: &[bool], w: usize, h: usize) -> Vec<Polyline> {
    // Corner (x, y) of the padded grid is pixel (x − 1, y − 1).
    let at =
        |x: usize, y: usize| x >= 1 && y >= 1 && x <= w && y <= h && dark[(y - 1) * w + (x - 1)];
    // Each cell's crossing segments, as edges between midpoints of cell
    // sides, joined into loops through a map of where each starts.
    let mut next: std::collections::HashMap<(usize, usize, u8), (usize, usize, u8)> =
        Default::default();
    for y in 0..=h {
        for x in 0..=w {
            let case = (at(x, y) as u8)
                | (at(x + 1, y) as u8) << 1
                | (at(x + 1, y + 1) as u8) << 2
                | (at(x, y + 1) as u8) << 3;
            // Sides: 0 top, 1 right, 2 bottom, 3 left. Dark on the left of
            // each directed segment.
            let segments: &[(u8, u8)] = match case {
                1 => &[(3, 0)],
                2 => &[(0, 1)],
                3 => &[(3, 1)],
                4 => &[(1, 2)],
                5 => &[(3, 2), (1, 0)],
                6 => &[(0, 2)],
                7 => &[(3, 2)],
                8 => &[(2, 3)],
                9 => &[(2, 0)],
                10 => &[(0, 3), (2, 1)],
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
    // A side is shared with the neighbouring cell: leaving by side b of
    // (x, y) is entering the neighbour by its opposite side.
    let enter = |(x, y, side): (usize, usize, u8)| match side {
        0 => (x, y.wrapping_sub(1), 2),
        1 => (x + 1, y, 3),
        2 => (x, y + 1, 0),
        _ => (x.wrapping_sub(1), y, 1),
    };
    let point = |(x, y, side): (usize, usize, u8)| {
        // Cell (x, y) spans pixel centres x − 0.5 … x + 0.5 (padded grid).
        let (cx, cy) = (x as f64 - 0.5, y as f64 - 0.5);
        match side {
            0 => [cx + 0.5, cy],
            1 => [cx + 1.0, cy + 0.5],
            2 => [cx + 0.5, cy + 1.0],
            _ => [cx, cy + 0.5],
        }
    };
    let mut starts: Vec<(usize, usize, u8)> = next.keys().copied().collect();
    starts.sort_unstable();
    let mut out = Vec::new();
    for start in starts {
        if !next.contains_key(&start) {
            continue;
        }
        let mut loop_ = vec![point(start)];
        let mut at = start;
        while let Some(exit) = next.remove(&at) {
            loop_.push(point(exit));
            at = enter(exit);
        }
        out.push(loop_);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_and_a_ring_become_one_chain_each() {
        let (w, h) = (20, 20);
        let mut e = vec![false; w * h];
        for x in 2..12 {
            e[3 * w + x] = true;
        }
        for (x, y) in [
            (10, 10),
            (11, 10),
            (12, 11),
            (12, 12),
            (11, 13),
            (10, 13),
            (9, 12),
            (9, 11),
        ] {
            e[y * w + x] = true;
        }
        let c = chains(&e, w, h);
        assert_eq!(c.len(), 2, "{c:?}");
        assert_eq!(c[0].len(), 10);
        assert_eq!(c[0][0], [2.5, 3.5]);
        // The ring closes on itself.
        assert_eq!(c[1].len(), 9);
        assert_eq!(c[1][0], c[1][8]);
    }

    #[test]
    fn a_dark_block_has_one_closed_outline_round_it() {
        let (w, h) = (10, 8);
        let mut d = vec![false; w * h];
        for y in 2..5 {
            for x in 3..7 {
                d[y * w + x] = true;
            }
        }
        let o = outlines(&d, w, h);
        assert_eq!(o.len(), 1);
        let ring = &o[0];
        assert_eq!(ring.first(), ring.last());
        // Halfway between the dark and the light pixel centres.
        let xs: Vec<f64> = ring.iter().map(|p| p[0]).collect();
        let (lo, hi) = (
            xs.iter().cloned().fold(f64::MAX, f64::min),
            xs.iter().cloned().fold(f64::MIN, f64::max),
        );
        assert_eq!((lo, hi), (3.0, 7.0));
        // A block with a hole: two loops.
        d[3 * w + 4] = false;
        d[3 * w + 5] = false;
        assert_eq!(outlines(&d, w, h).len(), 2);
    }
}
