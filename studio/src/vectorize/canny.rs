//! Canny's edge detector, as OpenCV's `Canny` (seed 002's vectoriser):
//! Gaussian smoothing, 3×3 Sobel gradients of the 0–255 grey levels,
//! non-maximum suppression across the gradient, then hysteresis — pixels
//! above `high` start edges, which run on through pixels above `low`.

use crate::gray::Gray;

/// One-pixel-thin edges of `image`: `true` on an edge.
pub fn edges(image: &Gray, sigma: f32, low: f32, high: f32) -> Vec<bool> {
    let (w, h) = (image.width, image.height);
    let levels: Vec<f32> = image.pixels.iter().map(|v| v * 255.0).collect();
    let smooth = if sigma > 0.0 {
        gaussian(&levels, w, h, sigma)
    } else {
        levels
    };
    let at = |x: isize, y: isize| {
        smooth[y.clamp(0, h as isize - 1) as usize * w + x.clamp(0, w as isize - 1) as usize]
    };
    let mut magnitude = vec![0.0f32; w * h];
    let mut sector = vec![0u8; w * h];
    for y in 0..h as isize {
        for x in 0..w as isize {
            let gx = at(x + 1, y - 1) + 2.0 * at(x + 1, y) + at(x + 1, y + 1)
                - at(x - 1, y - 1)
                - 2.0 * at(x - 1, y)
                - at(x - 1, y + 1);
            let gy = at(x - 1, y + 1) + 2.0 * at(x, y + 1) + at(x + 1, y + 1)
                - at(x - 1, y - 1)
                - 2.0 * at(x, y - 1)
                - at(x + 1, y - 1);
            let i = y as usize * w + x as usize;
            magnitude[i] = gx.hypot(gy);
            // The gradient's direction in four sectors: 0°, 45°, 90°, 135°.
            let a = gy.atan2(gx).to_degrees().rem_euclid(180.0);
            sector[i] = ((a + 22.5) / 45.0) as u8 % 4;
        }
    }
    // Keep only the ridge across the gradient.
    let mut thin = vec![0.0f32; w * h];
    for y in 1..h.saturating_sub(1) {
        for x in 1..w.saturating_sub(1) {
            let i = y * w + x;
            let m = magnitude[i];
            let (a, b) = match sector[i] {
                0 => (i - 1, i + 1),
                1 => (i - w - 1, i + w + 1),
                2 => (i - w, i + w),
                _ => (i - w + 1, i + w - 1),
            };
            // Ties broken one way, as OpenCV does, so plateaus stay thin.
            if m > magnitude[a] && m >= magnitude[b] {
                thin[i] = m;
            }
        }
    }
    // Hysteresis: grow from the strong pixels through the weak ones.
    let mut edge = vec![false; w * h];
    let mut stack: Vec<usize> = (0..w * h).filter(|&i| thin[i] >= high).collect();
    for &i in &stack {
        edge[i] = true;
    }
    while let Some(i) = stack.pop() {
        let (x, y) = ((i % w) as isize, (i / w) as isize);
        for (dx, dy) in NEIGHBOURS {
            let (nx, ny) = (x + dx, y + dy);
            if nx < 0 || ny < 0 || nx >= w as isize || ny >= h as isize {
                continue;
            }
            let j = ny as usize * w + nx as usize;
            if !edge[j] && thin[j] >= low {
                edge[j] = true;
                stack.push(j);
            }
        }
    }
    edge
}

/// The eight neighbours, the four sides first.
pub const NEIGHBOURS: [(isize, isize); 8] = [
    (1, 0),
    (0, 1),
    (-1, 0),
    (0, -1),
    (1, 1),
    (-1, 1),
    (-1, -1),
    (1, -1),
];

/// Separable Gaussian blur, edges clamped.
pub fn gaussian(data: &[f32], w: usize, h: usize, sigma: f32) -> Vec<f32> {
    let reach = (3.0 * sigma).ceil() as isize;
    let kernel: Vec<f32> = (-reach..=reach)
        .map(|k| (-(k * k) as f32 / (2.0 * sigma * sigma)).exp())
        .collect();
    let sum: f32 = kernel.iter().sum();
    let blur = |src: &[f32], along_x: bool| {
        let mut out = vec![0.0; src.len()];
        for y in 0..h {
            for x in 0..w {
                let mut acc = 0.0;
                for (k, wt) in kernel.iter().enumerate() {
                    let d = k as isize - reach;
                    let (sx, sy) = match along_x {
                        true => ((x as isize + d).clamp(0, w as isize - 1) as usize, y),
                        false => (x, (y as isize + d).clamp(0, h as isize - 1) as usize),
                    };
                    acc += wt * src[sy * w + sx];
                }
                out[y * w + x] = acc / sum;
            }
        }
        out
    };
    blur(&blur(data, true), false)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dark_square_gives_its_one_pixel_outline() {
        let mut g = Gray::new(40, 40, 1.0);
        for y in 10..30 {
            for x in 10..30 {
                g.pixels[y * 40 + x] = 0.0;
            }
        }
        let e = edges(&g, 1.0, 50.0, 150.0);
        // Along the left side, one pixel wide, at the step.
        let row: Vec<usize> = (0..40).filter(|&x| e[20 * 40 + x]).collect();
        assert_eq!(row.len(), 2, "{row:?}");
        assert!(
            (9..=10).contains(&row[0]) && (29..=30).contains(&row[1]),
            "{row:?}"
        );
        // Nothing in the flat parts.
        assert!(!e[20 * 40 + 20] && !e[2 * 40 + 2]);
        // Thresholds above every gradient: no edges at all.
        assert!(edges(&g, 1.0, 5000.0, 9000.0).iter().all(|&b| !b));
    }
}
