//! Our generator: greedy chords by squared error, then passes that move
//! single nails of the winding while that lowers the error.
//!
//! The thread's darkness is modelled as [`super::target`] renders it (each
//! chord leaves a pixel bare in the proportion 1 − w), so a chord's worth
//! is exactly how much it lowers Σ (wanted − rendered)² (kaspar98's
//! squared-error scoring, on an anti-aliased thread of the real width),
//! not a fixed weight subtracted from a residual. A chord over a pixel
//! with bare share T adds T·w of darkness: the error changes by
//! T·w·(T·w − 2·(wanted − (1 − T))).
//!
//! Greedy: from the nail the thread is on, the chord to the nail (at least
//! `min_separation` away) that lowers the error most, `lines` times.
//! Then each pass visits the nails of the winding in a seeded order and
//! tries moving nail k to its neighbours within `window`: the two chords
//! through it are taken away and the best of the candidates put back
//! (the present nail wins ties). The winding stays one thread, with the
//! same number of lines.

use super::target::{far_enough, Target};
use indicatif::ProgressBar;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Settings {
    pub lines: usize,
    /// Least distance round the ring between the two nails of a chord.
    pub min_separation: u16,
    /// Passes of single-nail moves after the greedy choice.
    pub passes: usize,
    /// How far (in nails) a pass may move a nail.
    pub window: u16,
    /// Orders the passes' visits.
    pub seed: u64,
}

/// The thread's state on the raster.
struct Loom<'a> {
    target: &'a Target,
    /// Bare share of each pixel; 0 outside the ring, where no pixel counts.
    bare: Vec<f32>,
    /// Wanted darkness − 1, so that the residual is `want1 + bare`.
    want1: Vec<f32>,
}

impl<'a> Loom<'a> {
    fn new(target: &'a Target) -> Loom<'a> {
        let mask = &target.frame.mask;
        Loom {
            bare: mask.iter().map(|&m| if m { 1.0 } else { 0.0 }).collect(),
            want1: target.darkness.iter().map(|d| d - 1.0).collect(),
            target,
        }
    }

    /// How much the chord `a`–`b` would change the squared error.
    #[inline]
    fn gain(&self, a: u16, b: u16) -> f32 {
        let (bare, want1) = (&self.bare[..], &self.want1[..]);
        let mut sum = 0.0;
        self.target.chord(a, b, |i, w| {
            let t = bare[i];
            let tw = t * w;
            sum += tw * (tw - 2.0 * (want1[i] + t));
        });
        sum
    }

    fn add(&mut self, a: u16, b: u16) {
        let bare = &mut self.bare;
        self.target.chord(a, b, |i, w| bare[i] *= 1.0 - w);
    }

    fn remove(&mut self, a: u16, b: u16) {
        let bare = &mut self.bare;
        self.target.chord(a, b, |i, w| bare[i] /= 1.0 - w);
    }
}

/// The winding: `settings.lines` nails after nail 0, where the thread is
/// tied. `progress` counts lines, then pass visits.
pub fn wind(target: &Target, settings: &Settings, progress: &ProgressBar) -> Result<Vec<u16>, String> {
    let n = target.nails();
    let min = settings.min_separation.max(1);
    if n / 2 < min {
        return Err(format!(
            "no chord possible: {n} nails cannot keep {min} nails apart both ways round"
        ));
    }
    let mut loom = Loom::new(target);
    let mut pattern = Vec::with_capacity(settings.lines);
    let mut at = 0u16;
    progress.set_length(settings.lines as u64);
    for _ in 0..settings.lines {
        let best = best_from(&loom, at, min);
        loom.add(at, best);
        pattern.push(best);
        at = best;
        progress.inc(1);
    }
    let mut rng = Rng::new(settings.seed);
    for _ in 0..settings.passes {
        progress.reset();
        progress.set_length(pattern.len() as u64);
        let moved = improve(&mut loom, &mut pattern, settings, min, &mut rng, progress);
        if moved == 0 {
            break;
        }
    }
    Ok(pattern)
}

/// The nail the chord from `at` should go to: least gain, the lowest
/// index among equals. The candidates are split between the two cores.
fn best_from(loom: &Loom<'_>, at: u16, min: u16) -> u16 {
    let n = loom.target.nails();
    let candidates: Vec<u16> = (0..n).filter(|&b| far_enough(at, b, n, min)).collect();
    let best_of = |part: &[u16]| {
        part.iter()
            .map(|&b| (loom.gain(at, b), b))
            .fold((f32::INFINITY, u16::MAX), |best, c| if c.0 < best.0 { c } else { best })
    };
    if candidates.len() < 64 {
        return best_of(&candidates).1;
    }
    let (left, right) = candidates.split_at(candidates.len() / 2);
    let (l, r) = std::thread::scope(|s| {
        let other = s.spawn(|| best_of(right));
        (best_of(left), other.join().expect("chord search"))
    });
    // Left holds the lower indices: it wins ties.
    if r.0 < l.0 {
        r.1
    } else {
        l.1
    }
}

/// One pass of single-nail moves; returns how many nails moved.
fn improve(
    loom: &mut Loom<'_>,
    pattern: &mut [u16],
    settings: &Settings,
    min: u16,
    rng: &mut Rng,
    progress: &ProgressBar,
) -> usize {
    let n = loom.target.nails();
    let mut order: Vec<usize> = (0..pattern.len()).collect();
    rng.shuffle(&mut order);
    let mut moved = 0;
    for k in order {
        let prev = if k == 0 { 0 } else { pattern[k - 1] };
        let next = pattern.get(k + 1).copied();
        let here = pattern[k];
        loom.remove(prev, here);
        if let Some(x) = next {
            loom.remove(here, x);
        }
        let cost = |loom: &Loom<'_>, c: u16| {
            let fits = far_enough(prev, c, n, min) && next.is_none_or(|x| far_enough(c, x, n, min));
            fits.then(|| loom.gain(prev, c) + next.map_or(0.0, |x| loom.gain(c, x)))
        };
        let mut best = (cost(loom, here).expect("the present nail fits"), here);
        for d in 1..=settings.window.min(n / 2) {
            for c in [(here + d) % n, (here + n - d) % n] {
                if let Some(g) = cost(loom, c) {
                    if g < best.0 {
                        best = (g, c);
                    }
                }
            }
        }
        let c = best.1;
        loom.add(prev, c);
        if let Some(x) = next {
            loom.add(c, x);
        }
        if c != here {
            pattern[k] = c;
            moved += 1;
        }
        progress.inc(1);
    }
    moved
}

/// The darkness the pattern leaves, for checks: equal to
/// [`Target::render`] up to rounding.
#[cfg(test)]
fn loom_darkness(target: &Target, pattern: &[u16]) -> Vec<f32> {
    let mut loom = Loom::new(target);
    for (a, b) in super::target::chords(pattern) {
        loom.add(a, b);
    }
    loom.bare.iter().zip(&target.frame.mask).map(|(t, &m)| if m { 1.0 - t } else { 0.0 }).collect()
}

/// A small seeded generator (xorshift64*): the same pattern for the same
/// seed, on every machine.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in `0..n` (n > 0).
    pub fn below(&mut self, n: u64) -> u64 {
        ((u128::from(self.next_u64()) * u128::from(n)) >> 64) as u64
    }

    pub fn shuffle<T>(&mut self, items: &mut [T]) {
        for i in (1..items.len()).rev() {
            let j = self.below(i as u64 + 1) as usize;
            items.swap(i, j);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gray::Gray;
    use crate::stringart::target::chords;
    use taut_logic::geometry::Board;
    use taut_logic::units::Milli;

    fn target(nails: u16) -> Target {
        // A dark bar across a white ground.
        let mut g = Gray::new(64, 64, 1.0);
        for y in 28..36 {
            for x in 0..64 {
                g.pixels[y * 64 + x] = 0.0;
            }
        }
        let board = Board::new(0, nails, Milli(115_000)).unwrap();
        Target::new(&g, board, 64, 3.0)
    }

    fn settings(lines: usize, passes: usize) -> Settings {
        Settings { lines, min_separation: 3, passes, window: 4, seed: 7 }
    }

    #[test]
    fn the_first_chord_lies_along_the_dark_bar() {
        let t = target(36);
        let p = wind(&t, &settings(1, 0), &ProgressBar::hidden()).unwrap();
        // From nail 0 (right) the bar's chord ends at nail 18 (left).
        assert_eq!(p, [18]);
    }

    #[test]
    fn passes_never_raise_the_error_and_keep_the_rules() {
        let t = target(40);
        let greedy = wind(&t, &settings(60, 0), &ProgressBar::hidden()).unwrap();
        let better = wind(&t, &settings(60, 3), &ProgressBar::hidden()).unwrap();
        assert_eq!(better.len(), 60);
        for (a, b) in chords(&better) {
            assert!(far_enough(a, b, 40, 3), "{a}–{b}");
        }
        let err = |p: &[u16]| {
            let r = t.render(p);
            r.iter().zip(&t.darkness).map(|(a, b)| f64::from(a - b).powi(2)).sum::<f64>()
        };
        assert!(err(&better) <= err(&greedy) + 1e-6, "{} > {}", err(&better), err(&greedy));
        // The loom's running state is the rendering inside the ring, up to
        // rounding.
        let (a, b) = (loom_darkness(&t, &better), t.render(&better));
        let inside = a.iter().zip(&b).zip(&t.frame.mask).filter(|(_, &m)| m);
        assert!(inside.map(|((x, y), _)| (x - y).abs()).fold(0.0, f32::max) < 1e-4);
    }

    #[test]
    fn too_few_nails_for_the_separation_is_an_error() {
        let t = target(5);
        let e = wind(&t, &settings(3, 0), &ProgressBar::hidden()).unwrap_err();
        assert!(e.contains("5 nails cannot keep 3 nails apart"), "{e}");
    }
}
