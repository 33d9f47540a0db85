//! The picture as the ring of nails sees it: which square of it (zoom and
//! offset), with what tones (contrast, gamma, inverted), and where the
//! thread matters most (an importance mask).
//!
//! The square is the picture's shorter side divided by `zoom`, centred at
//! the picture's centre moved by `offset` (fractions of the shorter side,
//! x right, y up); what it takes from beyond the picture is white. Tones:
//! inverted first, then contrast about mid-grey, then the gamma curve
//! (grey^gamma: above 1 darkens the midtones). A mask (a picture framed
//! the same way) keeps the darkness where it is white and halves it where
//! it is black, so the winding spends its thread on what the mask shows
//! (a face).

use crate::gray::Gray;

#[derive(Clone, Debug, PartialEq)]
pub struct Framing {
    pub zoom: f64,
    pub offset: [f64; 2],
    pub contrast: f32,
    pub gamma: f32,
    pub invert: bool,
}

impl Default for Framing {
    fn default() -> Framing {
        Framing {
            zoom: 1.0,
            offset: [0.0, 0.0],
            contrast: 1.0,
            gamma: 1.0,
            invert: false,
        }
    }
}

impl Framing {
    pub fn check(&self) -> Result<(), String> {
        if !(self.zoom > 0.0 && self.zoom <= 100.0) {
            return Err("--zoom must be above 0 and at most 100".into());
        }
        if !(self.contrast >= 0.0 && self.gamma > 0.0) {
            return Err("--contrast must be 0 or more, --gamma above 0".into());
        }
        Ok(())
    }

    /// The square the ring sees, `side` pixels across (the picture's
    /// resolution when 0).
    pub fn crop(&self, image: &Gray) -> Gray {
        let short = image.width.min(image.height) as f64;
        let side = (short / self.zoom).max(1.0);
        let centre = [
            image.width as f64 / 2.0 + self.offset[0] * short,
            image.height as f64 / 2.0 - self.offset[1] * short,
        ];
        let n = side.round().max(1.0) as usize;
        let k = side / n as f64;
        let mut out = Gray::new(n, n, 1.0);
        for y in 0..n {
            for x in 0..n {
                let sx = centre[0] - side / 2.0 + (x as f64 + 0.5) * k;
                let sy = centre[1] - side / 2.0 + (y as f64 + 0.5) * k;
                if sx >= 0.0
                    && sy >= 0.0
                    && (sx as usize) < image.width
                    && (sy as usize) < image.height
                {
                    out.pixels[y * n + x] = image.at(sx as usize, sy as usize);
                }
            }
        }
        out
    }

    /// A grey level through the tone settings.
    pub fn tone(&self, g: f32) -> f32 {
        let g = if self.invert { 1.0 - g } else { g };
        let g = (0.5 + (g - 0.5) * self.contrast).clamp(0.0, 1.0);
        g.powf(self.gamma)
    }

    /// The picture framed and toned, with the mask's weight applied.
    pub fn apply(&self, image: &Gray, mask: Option<&Gray>) -> Gray {
        let mut out = self.crop(image);
        for p in out.pixels.iter_mut() {
            *p = self.tone(*p);
        }
        if let Some(m) = mask {
            let m = self.crop(m).resized(out.width, out.height);
            for (p, w) in out.pixels.iter_mut().zip(&m.pixels) {
                // Darkness × (½ + ½ · mask).
                let keep = 0.5 + 0.5 * w.clamp(0.0, 1.0);
                *p = 1.0 - (1.0 - *p) * keep;
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zoom_offset_and_tones() {
        // 40 × 20: black left half, white right half.
        let mut g = Gray::new(40, 20, 1.0);
        for y in 0..20 {
            g.pixels[y * 40..y * 40 + 20].fill(0.0);
        }
        let f = Framing::default();
        // The centre square: half black, half white.
        let c = f.crop(&g);
        assert_eq!((c.width, c.height), (20, 20));
        assert_eq!(c.at(5, 5), 0.0);
        assert_eq!(c.at(15, 5), 1.0);
        // Moved left by a quarter of the short side: all black.
        let left = Framing {
            offset: [-0.5, 0.0],
            ..Framing::default()
        }
        .crop(&g);
        assert!(left.pixels.iter().all(|&p| p == 0.0));
        // Zoomed out ×0.5: 40 px square, paper beyond the picture.
        let out = Framing {
            zoom: 0.5,
            ..Framing::default()
        }
        .crop(&g);
        assert_eq!(out.width, 40);
        assert_eq!(out.at(20, 2), 1.0);
        assert_eq!(out.at(5, 15), 0.0);
        // Tones.
        let t = Framing {
            invert: true,
            contrast: 2.0,
            gamma: 2.0,
            ..Framing::default()
        };
        assert_eq!(t.tone(1.0), 0.0);
        assert!((t.tone(0.4) - 0.49).abs() < 1e-6);
        assert!(Framing {
            zoom: 0.0,
            ..Framing::default()
        }
        .check()
        .is_err());
    }

    #[test]
    fn a_mask_halves_the_darkness_it_leaves_out() {
        let g = Gray::new(10, 10, 0.0);
        let mut m = Gray::new(10, 10, 1.0);
        m.pixels[..50].fill(0.0);
        let out = Framing::default().apply(&g, Some(&m));
        assert!((out.at(5, 2) - 0.5).abs() < 1e-6);
        assert_eq!(out.at(5, 7), 0.0);
    }
}
