//! Adding a chord's blurred darkening to the generator's field: F += K∗δ
//! for the δ of each pixel the chord darkened, K a Gaussian.
//!
//! K is separable, so the δ are blurred along one axis into a scratch
//! raster, then along the other into F: for a chord of n pixels that costs
//! about 2·(2r + 1) per pixel plus the band the chord sweeps, instead of
//! (2r + 1)² per pixel. The first pass runs along the chord's longer
//! extent, where its pixels share lines. The second pass's rows of F are
//! split between the two cores.

pub struct Spread {
    size: usize,
    /// One side of K: 2·reach + 1 weights, summing to one.
    kernel: Vec<f32>,
    reach: usize,
    /// All zero between calls.
    scratch: Vec<f32>,
    /// Per line of the first pass, the first and last cell it touched.
    extent: Vec<(usize, usize)>,
    lines: Vec<usize>,
}

impl Spread {
    /// K of deviation `sigma` pixels, cut at 3σ, on a `size`² raster.
    pub fn new(size: usize, sigma: f32) -> Spread {
        let reach = (3.0 * sigma).ceil() as usize;
        let kernel: Vec<f32> = (0..=2 * reach)
            .map(|k| {
                let d = k as f32 - reach as f32;
                (-(d * d) / (2.0 * sigma * sigma)).exp()
            })
            .collect();
        let sum: f32 = kernel.iter().sum();
        Spread {
            size,
            kernel: kernel.iter().map(|k| k / sum).collect(),
            reach,
            scratch: vec![0.0; size * size],
            extent: vec![(usize::MAX, 0); size],
            lines: Vec::new(),
        }
    }

    /// `field += K∗δ` for each `(pixel, δ)` of `touched`.
    pub fn add(&mut self, field: &mut [f32], touched: &[(usize, f32)]) {
        let size = self.size;
        let rows_first = span(touched, |i| i % size) >= span(touched, |i| i / size);
        let (r, k) = (self.reach, &self.kernel[..]);
        // First pass: along rows (or columns) into the scratch.
        for &(i, d) in touched {
            let (line, at) = if rows_first {
                (i / size, i % size)
            } else {
                (i % size, i / size)
            };
            let (lo, hi) = (at.saturating_sub(r), (at + r).min(size - 1));
            for p in lo..=hi {
                let cell = if rows_first {
                    line * size + p
                } else {
                    p * size + line
                };
                self.scratch[cell] += d * k[p + r - at];
            }
            let e = &mut self.extent[line];
            if e.0 == usize::MAX {
                self.lines.push(line);
            }
            *e = (e.0.min(lo), e.1.max(hi));
        }
        // Second pass: across, into the two halves of F.
        let mid = size / 2;
        let (top, bottom) = field.split_at_mut(mid * size);
        let job = Across {
            size,
            kernel: k,
            reach: r,
            scratch: &self.scratch,
            extent: &self.extent,
            lines: &self.lines,
            rows_first,
        };
        rayon::join(|| job.fill(top, 0), || job.fill(bottom, mid));
        for &line in &self.lines {
            let (lo, hi) = std::mem::replace(&mut self.extent[line], (usize::MAX, 0));
            for p in lo..=hi {
                let cell = if rows_first {
                    line * size + p
                } else {
                    p * size + line
                };
                self.scratch[cell] = 0.0;
            }
        }
        self.lines.clear();
    }
}

/// How far apart the touched pixels lie along one axis (`along` of the
/// pixel index).
fn span(touched: &[(usize, f32)], along: impl Fn(usize) -> usize) -> usize {
    let (lo, hi) = touched.iter().fold((usize::MAX, 0), |(lo, hi), &(i, _)| {
        (lo.min(along(i)), hi.max(along(i)))
    });
    hi.saturating_sub(lo)
}

/// The second pass, shared by the two halves.
#[derive(Clone, Copy)]
struct Across<'a> {
    size: usize,
    kernel: &'a [f32],
    reach: usize,
    scratch: &'a [f32],
    extent: &'a [(usize, usize)],
    lines: &'a [usize],
    rows_first: bool,
}

impl Across<'_> {
    /// The rows of F from `first` on, held in `rows`.
    fn fill(&self, rows: &mut [f32], first: usize) {
        let (size, r) = (self.size, self.reach);
        let last = first + rows.len() / size;
        for &line in self.lines {
            let (lo, hi) = self.extent[line];
            for p in lo..=hi {
                let (x, y) = if self.rows_first {
                    (p, line)
                } else {
                    (line, p)
                };
                let h = self.scratch[y * size + x];
                if h == 0.0 {
                    continue;
                }
                if self.rows_first {
                    // Down the column x, within these rows.
                    for yy in y.saturating_sub(r).max(first)..(y + r + 1).min(last) {
                        rows[(yy - first) * size + x] += h * self.kernel[yy + r - y];
                    }
                } else if (first..last).contains(&y) {
                    // Along the row y.
                    let row = &mut rows[(y - first) * size..][..size];
                    let from = x.saturating_sub(r);
                    let cells = &mut row[from..=(x + r).min(size - 1)];
                    for (xx, cell) in (from..).zip(cells) {
                        *cell += h * self.kernel[xx + r - x];
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::blur;

    #[test]
    fn the_spread_is_the_blur_of_the_darkening() {
        let size = 40;
        for touched in [
            // A shallow run, a steep one, a diagonal, one near the corner.
            (5..35).map(|x| (20 * size + x, 0.3)).collect::<Vec<_>>(),
            (2..38).map(|y| (y * size + 11 + y / 6, 0.2)).collect(),
            (0..40)
                .map(|k| (k * size + k, 0.1 + k as f32 * 0.01))
                .collect(),
            vec![(0, 1.0), (1, 0.5)],
        ] {
            let mut spread = Spread::new(size, 1.7);
            let mut field = vec![0.25; size * size];
            spread.add(&mut field, &touched);
            let mut delta = vec![0.0; size * size];
            for &(i, d) in &touched {
                delta[i] += d;
            }
            let want = blur(&delta, size, 1.7);
            let worst = field
                .iter()
                .zip(&want)
                .map(|(f, w)| (f - 0.25 - w).abs())
                .fold(0.0, f32::max);
            assert!(worst < 1e-6, "{worst}");
            assert!(spread.scratch.iter().all(|&s| s == 0.0) && spread.lines.is_empty());
        }
    }
}
