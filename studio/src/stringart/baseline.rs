//! The two windings ours is measured against, at the same nails, lines and
//! thread.
//!
//! - [`plain`]: the plain greedy method of kmmeerts' string-art generator
//!   as halfmonty/StringArtGenerator ports it. A residual starts as the
//!   picture's darkness; from the nail the thread is on, the chord whose
//!   pixels (one sample a pixel along it, not anti-aliased) hold the most
//!   residual wins; a fixed weight is taken off the residual along it; the
//!   last nails visited are skipped (kmmeerts keeps 20) so the thread does
//!   not ping-pong. The weight is [`PLAIN_WEIGHT`].
//! - [`random`]: a random walk of chords, the floor any method must clear.

use super::greedy::Rng;
use super::target::{far_enough, Target};
use indicatif::ProgressBar;
use std::collections::VecDeque;

/// What a chord takes off the residual darkness: 20/255, the usual
/// setting of the ports. (On `camera.jpg`, 250 nails, 3000 lines, 0.3 mm
/// thread, weights of 8, 13, 20, 31, 51 and 77/255 give RMSEs of 0.241,
/// 0.229, 0.231, 0.239, 0.249 and 0.272: 20 is within 1 % of the best.)
pub const PLAIN_WEIGHT: f32 = 20.0 / 255.0;

/// The plain greedy winding of `lines` chords.
pub fn plain(target: &Target, lines: usize, min: u16, progress: &ProgressBar) -> Vec<u16> {
    let n = target.nails();
    let mut residual = target.darkness.clone();
    let recent_len = usize::from(n / 8).min(20);
    let mut recent: VecDeque<u16> = VecDeque::with_capacity(recent_len + 1);
    let mut pixels = Vec::new();
    let (mut at, mut pattern) = (0u16, Vec::with_capacity(lines));
    progress.set_length(lines as u64);
    for _ in 0..lines {
        let mut best = (f32::NEG_INFINITY, None);
        for b in (0..n).filter(|&b| far_enough(at, b, n, min.max(1)) && !recent.contains(&b)) {
            samples(target, at, b, &mut pixels);
            let sum: f32 = pixels.iter().map(|&i| residual[i]).sum();
            if sum > best.0 {
                best = (sum, Some(b));
            }
        }
        // Every nail recently visited: forget the oldest and go on.
        let Some(b) = best.1 else {
            recent.pop_front();
            continue;
        };
        samples(target, at, b, &mut pixels);
        for &i in &pixels {
            residual[i] = (residual[i] - PLAIN_WEIGHT).max(0.0);
        }
        pattern.push(b);
        recent.push_back(b);
        if recent.len() > recent_len {
            recent.pop_front();
        }
        at = b;
        progress.inc(1);
    }
    pattern
}

/// The pixels under the chord `a`–`b`: one sample a pixel of its length,
/// truncated to the pixel (numpy's `linspace(…, dtype=int)`), repeats
/// dropped.
fn samples(target: &Target, a: u16, b: u16, out: &mut Vec<usize>) {
    let (p, q) = (
        target.frame.nails[a as usize],
        target.frame.nails[b as usize],
    );
    let size = target.frame.size;
    let count = ((q[0] - p[0]).hypot(q[1] - p[1]) as usize).max(2);
    out.clear();
    for k in 0..count {
        let s = k as f32 / (count - 1) as f32;
        let x = (p[0] + (q[0] - p[0]) * s).clamp(0.0, size as f32 - 1.0) as usize;
        let y = (p[1] + (q[1] - p[1]) * s).clamp(0.0, size as f32 - 1.0) as usize;
        let i = y * size + x;
        if out.last() != Some(&i) {
            out.push(i);
        }
    }
}

/// `lines` chords, each to a nail drawn at random among those at least
/// `min` away.
pub fn random(nails: u16, lines: usize, min: u16, seed: u64) -> Vec<u16> {
    let mut rng = Rng::new(seed);
    let mut at = 0u16;
    (0..lines)
        .map(|_| {
            let choices: Vec<u16> = (0..nails)
                .filter(|&b| far_enough(at, b, nails, min.max(1)))
                .collect();
            at = choices[rng.below(choices.len() as u64) as usize];
            at
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gray::Gray;
    use taut_logic::geometry::Board;
    use taut_logic::units::Milli;

    #[test]
    fn plain_greedy_follows_the_dark_bar_first() {
        let mut g = Gray::new(64, 64, 1.0);
        g.pixels[30 * 64..34 * 64].fill(0.0);
        let board = Board::new(0, 36, Milli(115_000)).unwrap();
        let t = Target::new(&g, board, 64, 3.0);
        let p = plain(&t, 5, 3, &ProgressBar::hidden());
        assert_eq!(p[0], 18);
        assert_eq!(p.len(), 5);
        // Recently visited nails are skipped.
        assert!(p.windows(3).all(|w| w[0] != w[2]), "{p:?}");
    }

    #[test]
    fn random_chords_keep_the_separation_and_repeat_with_the_seed() {
        let a = random(30, 200, 5, 1);
        assert_eq!(a, random(30, 200, 5, 1));
        assert_ne!(a, random(30, 200, 5, 2));
        let mut at = 0;
        for &b in &a {
            assert!(far_enough(at, b, 30, 5));
            at = b;
        }
    }
}
