//! Grey levels: the ink/paper threshold from the picture's histogram
//! (Otsu's method), what kind of picture it is (line art, shapes or
//! tones), and the tone levels hatching draws at.

/// Otsu's threshold: the grey level (0–1) that splits the picture's 256-bin
/// histogram into the two classes with the largest variance between
/// them, and how well it splits (that variance over the whole picture's,
/// 0–1: near 1 for ink on paper, lower for a photograph).
pub fn otsu(pixels: &[f32]) -> (f32, f32) {
    let mut hist = [0u64; 256];
    for &p in pixels {
        hist[(p.clamp(0.0, 1.0) * 255.0).round() as usize] += 1;
    }
    let total = pixels.len().max(1) as f64;
    let sum: f64 = hist
        .iter()
        .enumerate()
        .map(|(i, &n)| i as f64 * n as f64)
        .sum();
    let mean = sum / total;
    let var: f64 = hist
        .iter()
        .enumerate()
        .map(|(i, &n)| n as f64 * (i as f64 - mean).powi(2))
        .sum::<f64>()
        / total;
    // The levels where the variance between is greatest: a picture of two
    // grey levels splits equally well anywhere between them, so the
    // middle of that run is taken.
    let (mut best, mut first, mut last) = (-1.0f64, 127usize, 127usize);
    let (mut w0, mut sum0) = (0.0, 0.0);
    for (t, &n) in hist.iter().enumerate().take(255) {
        w0 += n as f64;
        sum0 += t as f64 * n as f64;
        let w1 = total - w0;
        if w0 == 0.0 || w1 == 0.0 {
            continue;
        }
        let (m0, m1) = (sum0 / w0, (sum - sum0) / w1);
        let between = w0 * w1 * (m0 - m1).powi(2) / (total * total);
        if between > best * (1.0 + 1e-9) + 1e-15 {
            (best, first, last) = (between, t, t);
        } else if between >= best * (1.0 - 1e-9) {
            last = t;
        }
    }
    let best_t = (first + last) / 2;
    // Dark is below the level: between bin t and t + 1.
    let level = (best_t as f32 + 0.5) / 255.0;
    let separation = match var > 0.0 {
        true => (best.max(0.0) / var) as f32,
        false => 0.0,
    };
    (level, separation)
}

/// What a picture is, for `--mode auto`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// Thin dark lines on light paper: centre-lines.
    LineArt,
    /// Dark shapes on paper (a silhouette, a logo): outlines and hatching.
    Shapes,
    /// A photograph or a painting: tones.
    Tones,
}

/// The picture's kind: two-toned pictures (Otsu's separation ≥ 0.8) whose
/// dark parts are lines no wider than 3 % of the picture's shorter side
/// (at least 4 px, at most 12 px), mostly paper (dark under 35 %), are line art; other
/// two-toned pictures are shapes; the rest tones. The line width is twice
/// the mean depth of the dark pixels' skeleton (its distance to the
/// paper).
pub fn kind(pixels: &[f32], w: usize, h: usize, threshold: f32) -> Kind {
    let (_, separation) = otsu(pixels);
    if separation < 0.8 {
        return Kind::Tones;
    }
    let dark: Vec<bool> = pixels.iter().map(|&p| p < threshold).collect();
    let share = dark.iter().filter(|&&d| d).count() as f64 / dark.len().max(1) as f64;
    let depth = super::skeleton::distance(&dark, w, h);
    let skel = super::skeleton::thin(&dark, w, h);
    let on: Vec<f32> = (0..skel.len())
        .filter(|&i| skel[i])
        .map(|i| depth[i])
        .collect();
    if on.is_empty() {
        return Kind::Shapes;
    }
    // A line n pixels wide has its middle n/2 + ½ from the paper.
    let width = 2.0 * on.iter().sum::<f32>() / on.len() as f32 - 1.0;
    let limit = (0.03 * w.min(h) as f32).clamp(4.0, 12.0);
    match share < 0.35 && width <= limit {
        true => Kind::LineArt,
        false => Kind::Shapes,
    }
}

/// The levels hatching draws at, lightest first: `n` levels evenly from
/// `lightest` down (a pixel under k of them gets k sets of lines).
pub fn levels(lightest: f32, n: usize) -> Vec<f32> {
    (0..n)
        .map(|k| lightest * (n - k) as f32 / n as f32)
        .collect()
}

/// The share (0–1) of the picture's visibly grey or dark pixels (under
/// 0.85) that are lighter than `threshold`: not drawn.
pub fn vanished(pixels: &[f32], threshold: f32) -> f64 {
    let visible = pixels.iter().filter(|&&p| p < 0.85).count();
    let lost = pixels
        .iter()
        .filter(|&&p| p < 0.85 && p >= threshold)
        .count();
    match visible {
        0 => 0.0,
        v => lost as f64 / v as f64,
    }
}

/// The picture stretched so that its darkest 1 % is black and its
/// lightest 1 % white.
pub fn stretch(pixels: &[f32]) -> Vec<f32> {
    let mut sorted: Vec<f32> = pixels.to_vec();
    sorted.sort_by(|a, b| a.total_cmp(b));
    let at = |q: f64| sorted[((sorted.len() - 1) as f64 * q) as usize];
    let (lo, hi) = (at(0.01), at(0.99));
    if hi - lo < 1e-3 {
        return pixels.to_vec();
    }
    pixels
        .iter()
        .map(|&p| ((p - lo) / (hi - lo)).clamp(0.0, 1.0))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn otsu_splits_ink_from_paper() {
        // 30 % ink near 0.1, paper near 0.9.
        let mut p: Vec<f32> = (0..1000)
            .map(|i| {
                if i % 10 < 3 {
                    0.1 + (i % 7) as f32 * 0.01
                } else {
                    0.9 - (i % 5) as f32 * 0.01
                }
            })
            .collect();
        let (t, sep) = otsu(&p);
        assert!((0.16..0.86).contains(&t), "{t}");
        assert!(sep > 0.95, "{sep}");
        // A smooth ramp separates badly.
        p = (0..1000).map(|i| i as f32 / 999.0).collect();
        let (t, sep) = otsu(&p);
        assert!((t - 0.5).abs() < 0.02 && sep < 0.8, "{t} {sep}");
    }

    #[test]
    fn kinds_of_picture() {
        let (w, h) = (100, 100);
        let mut lines = vec![1.0f32; w * h];
        for y in 0..h {
            for x in 48..51 {
                lines[y * w + x] = 0.0;
            }
        }
        for x in 0..w {
            lines[20 * w + x] = 0.0;
            lines[21 * w + x] = 0.0;
        }
        assert_eq!(kind(&lines, w, h, 0.5), Kind::LineArt);
        let mut blob = vec![1.0f32; w * h];
        for y in 20..80 {
            for x in 20..80 {
                blob[y * w + x] = 0.0;
            }
        }
        assert_eq!(kind(&blob, w, h, 0.5), Kind::Shapes);
        let ramp: Vec<f32> = (0..w * h).map(|i| (i % w) as f32 / w as f32).collect();
        assert_eq!(kind(&ramp, w, h, 0.5), Kind::Tones);
        assert_eq!(levels(0.8, 4), [0.8, 0.6, 0.4, 0.2]);
        assert!((vanished(&ramp, 0.5) - 0.35 / 0.85).abs() < 0.02);
    }
}
