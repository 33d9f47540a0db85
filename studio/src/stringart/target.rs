//! What a winding is judged against: the picture as wanted darkness on the
//! board's raster, and the wound thread rendered at its real width.
//!
//! Thread over a pixel covers a share w of it (its width across the pixel,
//! anti-aliased); threads lie at random heights across a pixel, so k of
//! them leave it bare in the proportion Π(1 − wᵢ) and its darkness is one
//! minus that. The quality figure is the RMSE of darkness between target
//! and rendering, both blurred alike (as the eye blurs the piece from a
//! few steps away), over the pixels inside the ring.

use crate::board::Frame;
use crate::gray::Gray;
use crate::raster::{band, band_every, blur, rmse};
use taut_logic::geometry::Board;

/// No thread covers more of a pixel than this: bare area never reaches
/// zero, so a chord can be taken away again by division.
pub const MAX_COVER: f32 = 0.99;

pub struct Target {
    pub frame: Frame,
    /// Wanted darkness, 0 (bare board) to 1 (black); 0 outside the ring.
    pub darkness: Vec<f32>,
    pub thread_mm: f32,
    /// The thread's width on the raster, pixels.
    pub thread_px: f32,
}

impl Target {
    /// `image`, centred and scaled so that its shorter side spans the ring
    /// of nails, on a `size`² raster of `board`.
    pub fn new(image: &Gray, board: Board, size: usize, thread_mm: f32) -> Target {
        let frame = Frame::new(board, size);
        let picture = image.centre_square().resized(size, size);
        let darkness = picture
            .pixels
            .iter()
            .zip(&frame.mask)
            .map(|(&g, &inside)| if inside { 1.0 - g } else { 0.0 })
            .collect();
        Target {
            thread_px: frame.width_px(thread_mm),
            frame,
            darkness,
            thread_mm,
        }
    }

    pub fn nails(&self) -> u16 {
        self.frame.board.nails()
    }

    /// The pixels the thread from nail `a` to nail `b` covers, and how much
    /// of each.
    #[inline]
    pub fn chord(&self, a: u16, b: u16, mut f: impl FnMut(usize, f32)) {
        let (p, q) = (self.frame.nails[a as usize], self.frame.nails[b as usize]);
        let size = self.frame.size;
        band(p, q, self.thread_px, (size, size), |i, w| {
            f(i, w.min(MAX_COVER))
        });
    }

    /// [`Target::chord`] over every `stride`-th column (or row) only.
    #[inline]
    pub fn chord_sample(&self, a: u16, b: u16, stride: usize, mut f: impl FnMut(usize, f32)) {
        let (p, q) = (self.frame.nails[a as usize], self.frame.nails[b as usize]);
        let size = self.frame.size;
        band_every(p, q, self.thread_px, (size, size), stride, |i, w| {
            f(i, w.min(MAX_COVER))
        });
    }

    /// The darkness of the wound thread.
    pub fn render(&self, pattern: &[u16]) -> Vec<f32> {
        let mut bare = vec![1.0f32; self.darkness.len()];
        for (a, b) in chords(pattern) {
            self.chord(a, b, |i, w| bare[i] *= 1.0 - w);
        }
        bare.iter().map(|t| 1.0 - t).collect()
    }

    /// The blur of the quality figure: σ = 1/256 of the raster (2 pixels
    /// at 512), about a millimetre and a half on a 80 cm board.
    pub fn blur_sigma(&self) -> f32 {
        self.frame.size as f32 / 256.0
    }

    /// RMSE of darkness (0–1) between the target and the rendered
    /// `pattern`, both blurred, inside the ring.
    pub fn rmse(&self, pattern: &[u16]) -> f64 {
        let sigma = self.blur_sigma();
        let size = self.frame.size;
        let want = blur(&self.darkness, size, sigma);
        let got = blur(&self.render(pattern), size, sigma);
        rmse(&want, &got, &self.frame.mask)
    }
}

/// The chords of a winding: the thread is tied to nail 0, then goes to
/// each nail of the pattern in turn.
pub fn chords(pattern: &[u16]) -> impl Iterator<Item = (u16, u16)> + '_ {
    let from = std::iter::once(0).chain(pattern.iter().copied());
    from.zip(pattern.iter().copied())
}

/// Nails `a` and `b` are at least `min` apart round the ring.
pub fn far_enough(a: u16, b: u16, nails: u16, min: u16) -> bool {
    let d = a.abs_diff(b);
    d.min(nails - d) >= min
}

#[cfg(test)]
mod tests {
    use super::*;
    use taut_logic::units::Milli;

    #[test]
    fn chords_start_at_nail_zero() {
        let c: Vec<_> = chords(&[5, 9, 2]).collect();
        assert_eq!(c, [(0, 5), (5, 9), (9, 2)]);
        assert!(far_enough(1, 249, 250, 2) && !far_enough(1, 249, 250, 3));
    }

    #[test]
    fn a_blank_picture_wants_nothing_and_a_thread_darkens_its_line() {
        let board = Board::new(0, 24, Milli(115_000)).unwrap();
        let white = Gray::new(40, 30, 1.0);
        let t = Target::new(&white, board, 64, 2.0);
        assert!(t.darkness.iter().all(|&d| d == 0.0));
        assert_eq!(t.rmse(&[]), 0.0);
        // Nail 0 to nail 12 is the horizontal diameter: 64 px long, 0.64
        // px wide (2 mm at 3.125 mm a pixel).
        let dark = t.render(&[12]);
        let ink: f32 = dark.iter().sum();
        assert!((ink - 64.0 * 0.64).abs() < 1.0, "{ink}");
        assert!(t.rmse(&[12]) > 0.0);
    }
}
