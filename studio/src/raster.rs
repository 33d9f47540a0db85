//! Rasters: the pixels a thread or a pen line covers (anti-aliased, at its
//! real width), the RGB canvas previews are drawn on, PNG files, blur and
//! RMSE.

use std::path::Path;

/// A band `width` pixels wide along the segment `p`–`q` (pixel coordinates,
/// x right, y down): `f(index, coverage)` for every pixel it covers of a
/// `cols` × `rows` raster, coverage being the share of the pixel's area
/// under the band (0–1). Exact for each column the centre of which lies
/// between the ends (rows, for a steep segment); the ends themselves are
/// left square. A segment of no length covers nothing.
pub fn band(p: [f32; 2], q: [f32; 2], width: f32, dims: (usize, usize), f: impl FnMut(usize, f32)) {
    band_every(p, q, width, dims, 1, f)
}

/// [`band`] over every `stride`-th column (row, for a steep segment) only:
/// a sample of its pixels, for a quick estimate.
pub fn band_every(
    p: [f32; 2],
    q: [f32; 2],
    width: f32,
    (cols, rows): (usize, usize),
    stride: usize,
    mut f: impl FnMut(usize, f32),
) {
    let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
    if dx.abs() >= dy.abs() {
        if dx == 0.0 {
            return;
        }
        across(
            p[0],
            p[1],
            q[0],
            dy / dx,
            width,
            (cols, rows),
            stride,
            |u, v, w| f(v * cols + u, w),
        );
    } else {
        across(
            p[1],
            p[0],
            q[1],
            dx / dy,
            width,
            (rows, cols),
            stride,
            |v, u, w| f(v * cols + u, w),
        );
    }
}

/// One axis of [`band`]: the major coordinate runs from `a0` to `a1`
/// over `major` cells (every `stride`-th), the minor one starts at `b0`
/// with `slope`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn across(
    a0: f32,
    b0: f32,
    a1: f32,
    slope: f32,
    width: f32,
    (major, minor): (usize, usize),
    stride: usize,
    mut f: impl FnMut(usize, usize, f32),
) {
    let (lo_a, hi_a) = if a0 <= a1 { (a0, a1) } else { (a1, a0) };
    let first = ((lo_a - 0.5).ceil().max(0.0)) as usize;
    let last = (hi_a - 0.5).floor().min(major as f32 - 1.0);
    if last < first as f32 {
        return;
    }
    // The band's extent across one cell of the major axis.
    let half = 0.5 * width * (1.0 + slope * slope).sqrt();
    let top = minor as f32;
    for u in (first..=last as usize).step_by(stride) {
        let b = b0 + (u as f32 + 0.5 - a0) * slope;
        let (lo, hi) = ((b - half).max(0.0), (b + half).min(top));
        if hi <= lo {
            continue;
        }
        let mut v = lo as usize;
        while (v as f32) < hi {
            let w = hi.min(v as f32 + 1.0) - lo.max(v as f32);
            if w > 0.0 {
                f(u, v, w.min(1.0));
            }
            v += 1;
        }
    }
}

/// An RGB picture to draw previews on.
pub struct Canvas {
    pub cols: usize,
    pub rows: usize,
    /// Row-major RGB bytes.
    pub rgb: Vec<u8>,
}

pub type Rgb = [u8; 3];

impl Canvas {
    pub fn new(cols: usize, rows: usize, ground: Rgb) -> Canvas {
        Canvas {
            cols,
            rows,
            rgb: ground.repeat(cols * rows),
        }
    }

    /// Lays `color` over pixel `i` with opacity `alpha`.
    pub fn blend(&mut self, i: usize, color: Rgb, alpha: f32) {
        let px = &mut self.rgb[i * 3..][..3];
        for (old, new) in px.iter_mut().zip(color) {
            let (o, n) = (f32::from(*old), f32::from(new));
            *old = (o + (n - o) * alpha.min(1.0)).round() as u8;
        }
    }

    /// A line `width` pixels wide, anti-aliased.
    pub fn line(&mut self, p: [f32; 2], q: [f32; 2], width: f32, color: Rgb, alpha: f32) {
        let dims = (self.cols, self.rows);
        let mut hits = Vec::new();
        band(p, q, width, dims, |i, w| hits.push((i, w)));
        for (i, w) in hits {
            self.blend(i, color, w * alpha);
        }
    }

    /// A dashed line: `dash` pixels on, `dash` off, from `p`.
    pub fn dashed(&mut self, p: [f32; 2], q: [f32; 2], width: f32, color: Rgb, dash: f32) {
        let len = (q[0] - p[0]).hypot(q[1] - p[1]);
        let mut at = 0.0;
        while at < len {
            let end = (at + dash).min(len);
            let point = |s: f32| {
                [
                    p[0] + (q[0] - p[0]) * s / len,
                    p[1] + (q[1] - p[1]) * s / len,
                ]
            };
            self.line(point(at), point(end), width, color, 1.0);
            at += 2.0 * dash;
        }
    }

    /// A filled disc, its edge anti-aliased.
    pub fn disc(&mut self, c: [f32; 2], radius: f32, color: Rgb) {
        let (x0, x1) = (
            (c[0] - radius - 1.0).max(0.0),
            (c[0] + radius + 1.0).min(self.cols as f32),
        );
        let (y0, y1) = (
            (c[1] - radius - 1.0).max(0.0),
            (c[1] + radius + 1.0).min(self.rows as f32),
        );
        for y in y0 as usize..y1.max(0.0) as usize {
            for x in x0 as usize..x1.max(0.0) as usize {
                let d = (x as f32 + 0.5 - c[0]).hypot(y as f32 + 0.5 - c[1]);
                let alpha = (radius + 0.5 - d).clamp(0.0, 1.0);
                if alpha > 0.0 {
                    self.blend(y * self.cols + x, color, alpha);
                }
            }
        }
    }

    /// The canvas as PNG bytes.
    pub fn png(&self) -> Vec<u8> {
        encode_png(self.cols, self.rows, png::ColorType::Rgb, &self.rgb)
    }

    /// Written atomically (`output::write`).
    pub fn save_png(&self, path: &Path) -> Result<(), String> {
        crate::output::write(path, &self.png())
    }
}

/// 8-bit PNG of `data` (grey or RGB rows).
pub fn encode_png(cols: usize, rows: usize, color: png::ColorType, data: &[u8]) -> Vec<u8> {
    let mut bytes = Vec::new();
    let mut png = png::Encoder::new(&mut bytes, cols as u32, rows as u32);
    png.set_color(color);
    png.set_depth(png::BitDepth::Eight);
    // Encoding into memory fails only on a wrong buffer size: a bug.
    let mut writer = png.write_header().expect("PNG header");
    writer
        .write_image_data(data)
        .expect("PNG data of the canvas's size");
    writer.finish().expect("PNG end");
    bytes
}

/// A Gaussian blur of a `size` × `size` raster (zero beyond its edges).
pub fn blur(data: &[f32], size: usize, sigma: f32) -> Vec<f32> {
    let reach = (3.0 * sigma).ceil() as isize;
    let kernel: Vec<f32> = (-reach..=reach)
        .map(|k| (-(k * k) as f32 / (2.0 * sigma * sigma)).exp())
        .collect();
    let sum: f32 = kernel.iter().sum();
    let kernel: Vec<f32> = kernel.iter().map(|k| k / sum).collect();
    let pass = |src: &[f32], at: &dyn Fn(usize, usize) -> usize| {
        let mut out = vec![0.0; src.len()];
        for line in 0..size {
            for i in 0..size {
                let mut acc = 0.0;
                for (k, w) in kernel.iter().enumerate() {
                    let j = i as isize + k as isize - reach;
                    if (0..size as isize).contains(&j) {
                        acc += w * src[at(line, j as usize)];
                    }
                }
                out[at(line, i)] = acc;
            }
        }
        out
    };
    let rows = pass(data, &|line, i| line * size + i);
    pass(&rows, &|line, i| i * size + line)
}

/// Root mean square of `a − b` over the pixels where `mask` holds.
pub fn rmse(a: &[f32], b: &[f32], mask: &[bool]) -> f64 {
    let (mut sum, mut n) = (0.0f64, 0usize);
    for ((x, y), _) in a.iter().zip(b).zip(mask).filter(|(_, &m)| m) {
        sum += f64::from(x - y).powi(2);
        n += 1;
    }
    (sum / n.max(1) as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn covered(p: [f32; 2], q: [f32; 2], width: f32, size: usize) -> Vec<f32> {
        let mut out = vec![0.0; size * size];
        band(p, q, width, (size, size), |i, w| out[i] += w);
        out
    }

    #[test]
    fn a_band_covers_its_area_whatever_its_direction() {
        // A band of length L and width t covers L·t pixels of area, at
        // any angle (up to the square ends).
        for k in 0..24 {
            let a = k as f32 * std::f32::consts::TAU / 24.0 + 0.1;
            let (c, s) = (a.cos(), a.sin());
            let (p, q) = (
                [32.0 - 20.0 * c, 32.0 - 20.0 * s],
                [32.0 + 20.0 * c, 32.0 + 20.0 * s],
            );
            for t in [0.15f32, 0.7, 2.5] {
                let area: f32 = covered(p, q, t, 64).iter().sum();
                assert!(
                    (area - 40.0 * t).abs() < 1.5 * t,
                    "angle {a} width {t}: {area}"
                );
            }
        }
    }

    #[test]
    fn a_thin_horizontal_band_splits_between_two_rows() {
        let c = covered([0.0, 5.0], [10.0, 5.0], 0.4, 10);
        assert!((c[4 * 10 + 3] - 0.2).abs() < 1e-6 && (c[5 * 10 + 3] - 0.2).abs() < 1e-6);
        assert_eq!(c.iter().filter(|&&w| w > 0.0).count(), 20);
        // Off the raster, nothing; no length, nothing.
        assert!(covered([-5.0, -5.0], [-1.0, -3.0], 1.0, 10)
            .iter()
            .all(|&w| w == 0.0));
        assert!(covered([3.0, 3.0], [3.0, 3.0], 1.0, 10)
            .iter()
            .all(|&w| w == 0.0));
    }

    #[test]
    fn blur_keeps_a_flat_field_and_rmse_reads_the_mask() {
        let flat = vec![0.5; 32 * 32];
        let b = blur(&flat, 32, 1.5);
        assert!((b[16 * 32 + 16] - 0.5).abs() < 1e-5);
        assert!(b[0] < 0.5); // zero beyond the edge
        let mask: Vec<bool> = (0..32 * 32).map(|i| i % 2 == 0).collect();
        let other: Vec<f32> = (0..32 * 32)
            .map(|i| if i % 2 == 0 { 0.7 } else { 9.0 })
            .collect();
        assert!((rmse(&flat, &other, &mask) - 0.2).abs() < 1e-6);
    }
}
