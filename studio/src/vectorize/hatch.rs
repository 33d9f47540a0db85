//! Dark regions filled with parallel lines: scan lines `spacing` pixels
//! apart at `angle`, drawn wherever they cross dark pixels.

use super::trace::Polyline;

/// The hatch lines over the pixels where `dark` holds (pixel coordinates,
/// y down; `angle` in degrees, counter-clockwise as seen).
pub fn hatch(dark: &[bool], w: usize, h: usize, spacing: f64, angle: f64) -> Vec<Polyline> {
    let a = angle.to_radians();
    // Along the lines, and across them (y down: counter-clockwise is −y).
    let (u, n) = ([a.cos(), -a.sin()], [a.sin(), a.cos()]);
    let corners = [
        [0.0, 0.0],
        [w as f64, 0.0],
        [0.0, h as f64],
        [w as f64, h as f64],
    ];
    let span = |d: [f64; 2]| {
        let proj = corners.map(|c| c[0] * d[0] + c[1] * d[1]);
        (
            proj.iter().cloned().fold(f64::MAX, f64::min),
            proj.iter().cloned().fold(f64::MIN, f64::max),
        )
    };
    let ((t0, t1), (o0, o1)) = (span(u), span(n));
    let is_dark = |p: [f64; 2]| {
        let (x, y) = (p[0].floor(), p[1].floor());
        x >= 0.0
            && y >= 0.0
            && (x as usize) < w
            && (y as usize) < h
            && dark[y as usize * w + x as usize]
    };
    let step = 0.5;
    let mut out = Vec::new();
    let mut offset = o0 + spacing / 2.0;
    while offset < o1 {
        let at = |t: f64| [n[0] * offset + u[0] * t, n[1] * offset + u[1] * t];
        let mut run: Option<f64> = None;
        let mut t = t0;
        while t <= t1 + step {
            match (is_dark(at(t)), run) {
                (true, None) => run = Some(t),
                (false, Some(s)) => {
                    if t - step - s >= 1.0 {
                        out.push(vec![at(s), at(t - step)]);
                    }
                    run = None;
                }
                _ => {}
            }
            t += step;
        }
        offset += spacing;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dark_block_gets_evenly_spaced_lines_inside_it() {
        let (w, h) = (30, 20);
        let mut d = vec![false; w * h];
        for y in 5..15 {
            for x in 10..20 {
                d[y * w + x] = true;
            }
        }
        let lines = hatch(&d, w, h, 2.0, 0.0);
        assert_eq!(lines.len(), 5);
        for l in &lines {
            assert!(
                l[0][1] >= 5.0 && l[0][1] < 15.0 && l[0][1] == l[1][1],
                "{l:?}"
            );
            assert!(
                (l[0][0] - 10.0).abs() <= 0.5 && (l[1][0] - 19.5).abs() <= 0.5,
                "{l:?}"
            );
        }
        // At 45° every point of every line is on a dark pixel.
        for l in hatch(&d, w, h, 1.5, 45.0) {
            for s in 0..=10 {
                let p = [
                    l[0][0] + (l[1][0] - l[0][0]) * s as f64 / 10.0,
                    l[0][1] + (l[1][1] - l[0][1]) * s as f64 / 10.0,
                ];
                assert!(d[p[1] as usize * w + p[0] as usize], "{p:?}");
            }
        }
    }
}
