//! The raster the picture is drawn on: anti-aliased lines, discs, rings
//! and the board's face, in board millimetres.

use std::f64::consts::TAU;

/// An RGB raster in board millimetres: centre in the middle, y up.
pub struct Canvas {
    pub size: u32,
    /// Pixels per mm.
    pub scale: f64,
    /// Row-major RGB bytes.
    pub rgb: Vec<u8>,
}

impl Canvas {
    pub(super) fn new(size: u32, scale: f64) -> Canvas {
        Canvas {
            size,
            scale,
            rgb: vec![255; (size * size * 3) as usize],
        }
    }

    fn px(&self, (x, y): (f64, f64)) -> (f64, f64) {
        let half = f64::from(self.size) / 2.0;
        (half + x * self.scale, half - y * self.scale)
    }

    fn blend(&mut self, x: i64, y: i64, color: [u8; 3], alpha: f64) {
        let n = i64::from(self.size);
        if alpha <= 0.0 || !(0..n).contains(&x) || !(0..n).contains(&y) {
            return;
        }
        let i = ((y * n + x) * 3) as usize;
        for (k, &c) in color.iter().enumerate() {
            let old = f64::from(self.rgb[i + k]);
            self.rgb[i + k] = (old + (f64::from(c) - old) * alpha.min(1.0)).round() as u8;
        }
    }

    /// Blends `color` into each pixel of the box `lo`–`hi` (pixels, one
    /// more all round) with the alpha `coverage(x, y)` of its centre.
    fn paint(
        &mut self,
        lo: (f64, f64),
        hi: (f64, f64),
        color: [u8; 3],
        coverage: impl Fn(f64, f64) -> f64,
    ) {
        let (x0, y0) = (lo.0.floor() as i64 - 1, lo.1.floor() as i64 - 1);
        let (x1, y1) = (hi.0.ceil() as i64 + 1, hi.1.ceil() as i64 + 1);
        let n = i64::from(self.size);
        for y in y0.max(0)..=y1.min(n - 1) {
            for x in x0.max(0)..=x1.min(n - 1) {
                let a = coverage(x as f64 + 0.5, y as f64 + 0.5);
                self.blend(x, y, color, a);
            }
        }
    }

    /// Anti-aliased segment, `width` px wide.
    pub(super) fn line(
        &mut self,
        p: (f64, f64),
        q: (f64, f64),
        width: f64,
        color: [u8; 3],
        alpha: f64,
    ) {
        let (a, b) = (self.px(p), self.px(q));
        let r = width / 2.0;
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let len2 = dx * dx + dy * dy;
        let coverage = |x: f64, y: f64| {
            let t = if len2 > 0.0 {
                (((x - a.0) * dx + (y - a.1) * dy) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let d = (x - a.0 - t * dx).hypot(y - a.1 - t * dy);
            (r + 0.5 - d).clamp(0.0, 1.0) * alpha
        };
        // Row by row, only the pixels the line can touch: a long diagonal's
        // bounding box is mostly empty.
        let n = i64::from(self.size);
        let reach = r + 2.0;
        let (y0, y1) = (a.1.min(b.1) - reach, a.1.max(b.1) + reach);
        for y in (y0.floor() as i64).max(0)..=(y1.ceil() as i64).min(n - 1) {
            let yc = y as f64 + 0.5;
            // The segment's x where it crosses this row, widened.
            let (xa, xb) = match dy.abs() > 1e-9 {
                true => {
                    let x_at = |yy: f64| a.0 + dx * ((yy - a.1) / dy).clamp(0.0, 1.0);
                    let slope = (dx / dy).abs();
                    let (u, v) = (x_at(yc - reach), x_at(yc + reach));
                    (
                        u.min(v) - reach * (1.0 + slope),
                        u.max(v) + reach * (1.0 + slope),
                    )
                }
                false => (a.0.min(b.0) - reach, a.0.max(b.0) + reach),
            };
            for x in (xa.floor() as i64).max(0)..=(xb.ceil() as i64).min(n - 1) {
                let c = coverage(x as f64 + 0.5, yc);
                self.blend(x, y, color, c);
            }
        }
    }

    /// A filled disc of `r` px.
    pub(super) fn dot(&mut self, centre: (f64, f64), r: f64, color: [u8; 3], alpha: f64) {
        let c = self.px(centre);
        self.paint((c.0 - r, c.1 - r), (c.0 + r, c.1 + r), color, |x, y| {
            (r + 0.5 - (x - c.0).hypot(y - c.1)).clamp(0.0, 1.0) * alpha
        });
    }

    /// A circle of `r` px, a pixel and a half wide.
    pub(super) fn ring(&mut self, centre: (f64, f64), r: f64, color: [u8; 3], alpha: f64) {
        let c = self.px(centre);
        self.paint(
            (c.0 - r - 1.0, c.1 - r - 1.0),
            (c.0 + r + 1.0, c.1 + r + 1.0),
            color,
            |x, y| (1.25 - ((x - c.0).hypot(y - c.1) - r).abs()).clamp(0.0, 1.0) * alpha,
        );
    }

    /// The board's face: inside the circle, or the polygon with a vertex
    /// at angle 0, of radius `radius`.
    pub(super) fn fill_board(&mut self, radius: f64, sides: Option<u32>, color: [u8; 3]) {
        let (half, scale) = (f64::from(self.size) / 2.0, self.scale);
        let sector = sides.map(|n| TAU / f64::from(n));
        self.paint((0.0, 0.0), (half * 2.0, half * 2.0), color, |x, y| {
            let (bx, by) = ((x - half) / scale, (half - y) / scale);
            let (r, a) = (bx.hypot(by), by.atan2(bx).rem_euclid(TAU));
            // Distance inside the edge, mm, along the sector's apothem.
            let inside = match sector {
                None => radius - r,
                Some(s) => {
                    let mid = (a / s).floor() * s + s / 2.0;
                    radius * (s / 2.0).cos() - r * (a - mid).cos()
                }
            };
            (inside * scale + 0.5).clamp(0.0, 1.0)
        });
    }
}
