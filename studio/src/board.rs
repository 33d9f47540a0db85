//! The string-art board on a square raster: the machine's own nail
//! positions (`taut_logic::geometry::Board`, the ones the firmware drills
//! and winds) in pixels, and the pixels inside the ring of nails.
//!
//! The raster spans the nail ring's circumradius (R − 1.5 cm) each way from
//! the board's centre: x right towards nail 0, y down, so image up is 90°
//! counter-clockwise from nail 0, as the board is seen from above.

use taut_logic::geometry::{Board, NAIL_MARGIN_MM};

pub struct Frame {
    pub board: Board,
    /// Pixels across.
    pub size: usize,
    /// The nail ring's circumradius, mm: the raster spans ± this.
    pub ring_mm: f32,
    pub mm_per_px: f32,
    /// Each nail's centre, pixels.
    pub nails: Vec<[f32; 2]>,
    /// The pixels whose centre lies inside the ring of nails (their convex
    /// hull): the only ones a chord can cross.
    pub mask: Vec<bool>,
}

impl Frame {
    pub fn new(board: Board, size: usize) -> Frame {
        let ring_mm = board.radius() - NAIL_MARGIN_MM;
        let mm_per_px = 2.0 * ring_mm / size as f32;
        let mut frame = Frame {
            board,
            size,
            ring_mm,
            mm_per_px,
            nails: Vec::new(),
            mask: Vec::new(),
        };
        frame.nails = (0..board.nails())
            .map(|i| {
                let [x, y] = nail_mm(&board, i);
                frame.px(x as f32, y as f32)
            })
            .collect();
        frame.mask = frame.inside_ring();
        frame
    }

    /// Board millimetres (x towards nail 0, y 90° counter-clockwise) to
    /// pixels.
    pub fn px(&self, x: f32, y: f32) -> [f32; 2] {
        [
            (x + self.ring_mm) / self.mm_per_px,
            (self.ring_mm - y) / self.mm_per_px,
        ]
    }

    /// The thread's width in pixels.
    pub fn width_px(&self, thread_mm: f32) -> f32 {
        thread_mm / self.mm_per_px
    }

    /// Pixel centres inside the convex ring of nails, each tested against
    /// the edge between the two nails its angle falls between (nail angles
    /// increase counter-clockwise from 0).
    fn inside_ring(&self) -> Vec<bool> {
        let nails: Vec<[f64; 2]> = (0..self.board.nails())
            .map(|i| nail_mm(&self.board, i))
            .collect();
        let angles: Vec<f64> = (0..self.board.nails())
            .map(|i| f64::from(self.board.nail(i).angle))
            .collect();
        let n = nails.len();
        let (ring, step) = (f64::from(self.ring_mm), f64::from(self.mm_per_px));
        let mut mask = vec![false; self.size * self.size];
        for (i, m) in mask.iter_mut().enumerate() {
            let x = -ring + ((i % self.size) as f64 + 0.5) * step;
            let y = ring - ((i / self.size) as f64 + 0.5) * step;
            let a = y.atan2(x).rem_euclid(std::f64::consts::TAU);
            let k = (angles.partition_point(|&b| b <= a) + n - 1) % n;
            let (p, q) = (nails[k], nails[(k + 1) % n]);
            *m = (q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0]) >= 0.0;
        }
        mask
    }
}

/// Nail `i`'s centre on the board, mm: x towards nail 0, y 90°
/// counter-clockwise from it.
pub fn nail_mm(board: &Board, i: u16) -> [f64; 2] {
    let n = board.nail(i);
    let (a, r) = (f64::from(n.angle), f64::from(n.radius));
    [r * a.cos(), r * a.sin()]
}

#[cfg(test)]
mod tests {
    use super::*;
    use taut_logic::units::Milli;

    #[test]
    fn nail_zero_is_right_and_nail_a_quarter_on_is_up() {
        let f = Frame::new(Board::new(0, 8, Milli(115_000)).unwrap(), 100);
        // R − 1.5 cm = 100 mm over 100 px: 2 mm a pixel.
        assert_eq!(f.mm_per_px, 2.0);
        assert_eq!(f.nails[0], [100.0, 50.0]);
        let up = f.nails[2];
        assert!((up[0] - 50.0).abs() < 1e-3 && up[1].abs() < 1e-3, "{up:?}");
        assert_eq!(f.width_px(0.5), 0.25);
    }

    #[test]
    fn the_mask_is_the_inside_of_the_ring() {
        let circle = Frame::new(Board::new(0, 250, Milli(115_000)).unwrap(), 64);
        let inside = circle.mask.iter().filter(|&&m| m).count() as f32;
        let disc = std::f32::consts::PI * 32.0 * 32.0;
        assert!((inside / disc - 1.0).abs() < 0.02, "{inside} vs {disc}");
        // A square board's nails lie on a square at 45°: half the raster.
        let square = Frame::new(Board::new(4, 40, Milli(115_000)).unwrap(), 64);
        let inside = square.mask.iter().filter(|&&m| m).count() as f32;
        assert!(
            (inside / (64.0 * 64.0 / 2.0) - 1.0).abs() < 0.03,
            "{inside}"
        );
        assert!(square.mask[32 * 64 + 32] && !square.mask[2 * 64 + 2]);
    }
}
