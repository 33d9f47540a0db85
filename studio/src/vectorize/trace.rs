//! From pixels to polylines (pixel coordinates, x right, y down):
//!
//! - [`chains`]: a one-pixel-thin edge map followed pixel to pixel, so each
//!   edge is drawn once (a border follower such as OpenCV's Suzuki–Abe
//!   `findContours` would go round a thin edge on both sides: twice the
//!   ink). Open chains start at their ends or junctions; what is left are
//!   closed loops.

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
}
