//! Tiny straight moves joined into one: a plotter's curve comes as
//! hundreds of chords of 0.05–0.2 mm, and each planned apart is a block
//! to plan, to cut and (on the arm and the whiteboard) to convert, and a
//! look-ahead of a dozen of them reaches a millimetre. Consecutive `G1`
//! moves at one feed are joined into one move while every vertex they
//! pass lies within the arc tolerance of the joined move (LinuxCNC's
//! `G64 Q` "naive CAM" tolerance; Grbl's `$12` bounds an arc's chords in
//! the same way), the move goes on along their direction, and it stays
//! within [`JOIN_SPAN_UM`] (half a piece on the arm and the whiteboard:
//! one piece). The joined move ends on the last line's exact target.
//!
//! The test is the sleeve of cones (Zhao and Saalfeld): from the joined
//! move's start, each vertex allows the directions passing within the
//! tolerance of it; a new end must lie in all of them. The cones'
//! intersection is kept as its two bounding directions.

use super::{motor_channels, motor_milli, todo, Env, Interpreter, MachineIo, Wait};
use crate::kinematics::{Kinematics, Position, Segmenter};
use crate::planner::Feed;
use crate::units::Milli;

/// The longest joined move, µm along any channel (under half of it: one
/// piece of a path, `Segmenter::is_one_piece`).
pub const JOIN_SPAN_UM: u32 = 4000;

/// A joined move not yet queued.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Join {
    /// Where the moves queued end: the joined move's start (µm).
    pub from: Position,
    /// The lines' feed (`G94`, mm per minute).
    pub feed: Milli,
    /// The directions from `from` passing within the tolerance of every
    /// vertex joined: counterclockwise from `lo` to `hi` (2¹³ to 2¹⁴
    /// long).
    lo: [i16; 2],
    hi: [i16; 2],
    /// The last vertex's squared distance from `from` (µm²): a new end
    /// must be no nearer.
    far2: i32,
}

/// `a × b`: over 0 when `b` is counterclockwise of `a`. Out of line:
/// the joins' one piece of arithmetic (a rotation, a square are crosses
/// too), 16 by 16 bits.
#[inline(never)]
fn cross(a: [i16; 2], b: [i16; 2]) -> i32 {
    a[0] as i32 * b[1] as i32 - a[1] as i32 * b[0] as i32
}

/// The plane's channels from `from` to `to`, µm; `None` if another
/// channel changes or the move leaves the span (each then under 2¹¹).
fn plane_delta(from: &Position, to: &Position, span_um: u32) -> Option<[i16; 2]> {
    if from[2] != to[2] || !Segmenter::is_one_piece(from, to, span_um) {
        return None;
    }
    Some([(to[0].0 - from[0].0) as i16, (to[1].0 - from[1].0) as i16])
}

impl Join {
    /// A join from `from` with no vertex yet: any direction goes, but the
    /// first vertex must lie over twice the tolerance `tol` (µm) away, to
    /// set one.
    fn new(from: &Position, feed: Milli, tol: u32) -> Join {
        Join {
            from: *from,
            feed,
            lo: [0; 2],
            hi: [0; 2],
            far2: (4 * tol * tol + 1) as i32,
        }
    }

    /// `to` as the joined move's new end, if every vertex so far lies
    /// within `tol` (µm, 1 to [`MAX_TOL_UM`]) of the move from `from`
    /// to it, and it is no nearer than the last; then its own cone is
    /// taken in. (A zero bound is no bound.)
    #[inline(never)]
    pub fn extend(&mut self, to: &Position, tol: u32, span_um: u32) -> bool {
        let Some(d) = plane_delta(&self.from, to, span_um) else {
            return false;
        };
        let r2 = cross(d, [-d[1], d[0]]);
        if r2 < self.far2 || cross(self.lo, d) < 0 || cross(d, self.hi) < 0 {
            return false;
        }
        let [lo, hi] = cone(d, r2, tol);
        // The narrower bound of each side (all within a right angle of
        // `d`: a cone is under 60° wide, its vertex over 2·tol away).
        if cross(self.lo, lo) >= 0 {
            self.lo = lo;
        }
        if cross(hi, self.hi) >= 0 {
            self.hi = hi;
        }
        self.far2 = r2;
        true
    }
}

/// The largest tolerance joins use (µm): the arc tolerance, up to this.
pub const MAX_TOL_UM: u32 = 1000;

impl Interpreter {
    /// Once a line is accepted: its one leg (`joins`: a plain `G1` at
    /// `feed`, nothing else to do) joins the moves before, or starts a
    /// join, if it can; otherwise the moves joined are queued first if
    /// the line moves or waits for motion (then a `joins` line may start
    /// a join of its own, [`Interpreter::open_join`]).
    #[inline(never)]
    pub(super) fn join_or_flush<K: Kinematics>(&mut self, joins: bool, env: &Env<K>) {
        if joins && self.run.todo == todo::LEG_0 {
            let fresh = self.join.is_none();
            if self.open_join(env) {
                self.run.todo = 0;
                self.run.opens = fresh;
                return;
            }
            // One that did not join the move before may start its own
            // once that is queued.
            self.run.opens = !fresh;
        }
        // `M114`, `M17`, `M18 S` neither move nor wait.
        let moves = todo::REPORT | todo::DRIVERS_ON | todo::IDLE_DELAY;
        if self.join.is_some() && self.run.todo & !moves != 0 {
            self.run.todo |= todo::FLUSH;
        }
    }

    /// The line's one leg, from `run.from` to the programmed position,
    /// into the join open (true), or as a new one if none is (true if it
    /// starts one); then `run.from` is its end. Nothing is queued.
    #[inline(never)]
    pub(super) fn open_join<K: Kinematics>(&mut self, env: &Env<K>) -> bool {
        let Feed::PerMinute(feed) = self.run.feed else {
            return false;
        };
        let tol = tolerance(env);
        // `$12=0`: no vertex may stray, so nothing is joined.
        if tol == 0 {
            return false;
        }
        let motors = motor_channels(env.cfg);
        let fresh = self.join.is_none();
        let from = &self.run.from;
        let j = self
            .join
            .get_or_insert_with(|| Join::new(&motor_milli(from, motors), feed, tol));
        if j.feed != feed || !j.extend(&motor_milli(&self.position, motors), tol, span(env)) {
            if fresh {
                self.join = None;
            }
            return false;
        }
        self.run.from = self.position;
        true
    }

    /// The joined move queued, from its start to `run.from` (the exact
    /// target of its last line): one move, or one piece.
    #[inline(never)]
    pub(super) fn flush<K: Kinematics>(
        &mut self,
        env: &Env<K>,
        io: &mut impl MachineIo,
    ) -> Option<Wait> {
        let join = self.join?;
        // `join.from` has the channels without a motor at 0 (`motor_milli`).
        let feed = Feed::PerMinute(join.feed);
        if let Some(wait) = self.queue_move(&join.from, &self.run.from, feed, env, io) {
            return Some(wait);
        }
        self.join = None;
        None
    }
}

/// The join's tolerance: the arc tolerance, µm.
fn tolerance<K: Kinematics>(env: &Env<K>) -> u32 {
    env.cfg.arc_tolerance_um.min(MAX_TOL_UM)
}

/// The longest joined move: one piece of a path.
fn span<K: Kinematics>(env: &Env<K>) -> u32 {
    env.kin.piece_um().min(JOIN_SPAN_UM)
}

/// The directions passing within `tol` of the vertex `d` (`r2` its
/// squared distance, over `4·tol²`): `d` turned by `∓asin(tol / r)`,
/// as vectors of 2¹³ to 2¹⁴ (`d` doubled until then). In integers, each
/// rounding narrower: the root up, `sin` down and for half a µm less
/// (the bounds' own rounding strays less), `cos` as `1 − sin²/2`, over
/// the true one.
fn cone(d: [i16; 2], r2: i32, tol: u32) -> [[i16; 2]; 2] {
    let mut r = crate::segment::isqrt32(r2 as u32);
    r += (r * r < r2 as u32) as u32;
    let s = (((tol << 14) - (1 << 13)) / r) as i16;
    let c = (1 << 14) - (cross([s, 0], [0, s]) >> 15) as i16;
    let (mut u, mut m2) = (d, r2);
    while m2 < 1 << 26 {
        u = [u[0] * 2, u[1] * 2];
        m2 *= 4;
    }
    // `u` turned by the angle of cosine `c`, sine `s` (2¹⁴ to 1).
    let turn = |s: i16| {
        let cs = [s, c];
        [
            (cross(u, cs) >> 14) as i16,
            (cross([u[1], -u[0]], cs) >> 14) as i16,
        ]
    };
    [turn(-s), turn(s)]
}

#[cfg(test)]
mod tests {
    use super::*;

    impl Join {
        fn start(
            from: &Position,
            to: &Position,
            feed: Milli,
            tol: u32,
            span_um: u32,
        ) -> Option<Join> {
            let mut j = Join::new(from, feed, tol);
            j.extend(to, tol, span_um).then_some(j)
        }
    }

    fn at(x: i32, y: i32) -> Position {
        [Milli(x), Milli(y), Milli(0)]
    }

    /// The distance (µm) of `p` from the segment `a`–`b`.
    fn off(a: &Position, b: &Position, p: &Position) -> f64 {
        let (ax, ay) = (a[0].0 as f64, a[1].0 as f64);
        let (dx, dy) = (b[0].0 as f64 - ax, b[1].0 as f64 - ay);
        let (px, py) = (p[0].0 as f64 - ax, p[1].0 as f64 - ay);
        let len2 = dx * dx + dy * dy;
        let t = ((px * dx + py * dy) / len2).clamp(0.0, 1.0);
        ((px - t * dx).powi(2) + (py - t * dy).powi(2)).sqrt()
    }

    #[test]
    fn a_circles_chords_join_while_the_vertices_stay_within_the_tolerance() {
        // 50 µm chords of a 20 mm circle, tolerance 10 µm: the sagitta
        // L²/8R reaches 10 µm at L ≈ 1.26 mm, some 25 chords.
        let r = 20_000.0f64;
        let p = |k: usize| {
            let a = k as f64 * 50.0 / r;
            at((r * a.cos()).round() as i32, (r * a.sin()).round() as i32)
        };
        let mut j = Join::start(&p(0), &p(1), Milli(1500), 10, JOIN_SPAN_UM).unwrap();
        let mut k = 2;
        while j.extend(&p(k), 10, JOIN_SPAN_UM) {
            k += 1;
        }
        let end = p(k - 1);
        assert!((20..=26).contains(&(k - 1)), "{} chords joined", k - 1);
        for i in 1..k {
            assert!(off(&p(0), &end, &p(i)) <= 10.0 + 1e-3, "vertex {i}");
        }
        // One chord more would leave a vertex out of the tolerance, less
        // the half µm the bounds keep for their rounding.
        let worst = (1..k).map(|i| off(&p(0), &p(k), &p(i))).fold(0.0, f64::max);
        assert!(worst > 9.5, "{worst}");
    }

    #[test]
    fn collinear_lines_join_up_to_the_span() {
        let mut j = Join::start(&at(0, 0), &at(100, 100), Milli(900), 10, JOIN_SPAN_UM).unwrap();
        let mut k = 2;
        while j.extend(&at(100 * k, 100 * k), 10, JOIN_SPAN_UM) {
            k += 1;
        }
        // Under half the span along each channel.
        assert_eq!(k - 1, 19);
    }

    #[test]
    fn a_corner_a_reversal_or_a_pen_move_ends_the_join() {
        let tol = 10;
        let j = Join::start(&at(0, 0), &at(200, 0), Milli(900), tol, JOIN_SPAN_UM).unwrap();
        // A right angle.
        assert!(!j.clone().extend(&at(200, 200), tol, JOIN_SPAN_UM));
        // Back along the line: nearer than the last vertex.
        assert!(!j.clone().extend(&at(100, 0), tol, JOIN_SPAN_UM));
        // The pen's channel changes.
        let mut z = at(400, 0);
        z[2] = Milli(-1000);
        assert!(!j.clone().extend(&z, tol, JOIN_SPAN_UM));
        // Within and just past the tolerance at the vertex (200, 0) for an
        // end at (400, y): the vertex is about y/2 off the line.
        assert!(j.clone().extend(&at(400, 18), tol, JOIN_SPAN_UM));
        assert!(!j.clone().extend(&at(400, 21), tol, JOIN_SPAN_UM));
        assert!(j.clone().extend(&at(400, -18), tol, JOIN_SPAN_UM));
        assert!(!j.clone().extend(&at(400, -21), tol, JOIN_SPAN_UM));
    }

    #[test]
    fn a_line_within_twice_the_tolerance_starts_no_join() {
        assert!(Join::start(&at(0, 0), &at(20, 0), Milli(900), 10, JOIN_SPAN_UM).is_none());
        assert!(Join::start(&at(0, 0), &at(21, 0), Milli(900), 10, JOIN_SPAN_UM).is_some());
        // Longer than half the span.
        assert!(Join::start(&at(0, 0), &at(2000, 0), Milli(900), 10, JOIN_SPAN_UM).is_none());
    }

    proptest::proptest! {
        /// Any stream of short moves, joined as the executor joins them:
        /// every vertex of a joined move lies within the tolerance of the
        /// straight move from its start to its end, and the move goes on
        /// along the way (no vertex past its end).
        #[test]
        fn every_joined_vertex_lies_within_the_tolerance(
            steps in proptest::collection::vec((1i32..400, -300i32..300), 2..200),
            tol in 1u32..60,
        ) {
            let mut at = at(0, 0);
            let mut heading = 0.0f64;
            let mut points = std::vec![at];
            for (len, turn) in &steps {
                heading += *turn as f64 / 1000.0;
                at = [
                    Milli(at[0].0 + (*len as f64 * heading.cos()).round() as i32),
                    Milli(at[1].0 + (*len as f64 * heading.sin()).round() as i32),
                    Milli(0),
                ];
                points.push(at);
            }
            let mut start = 0;
            while start + 1 < points.len() {
                let mut j = Join::new(&points[start], Milli(1000), tol);
                let mut end = start;
                while end + 1 < points.len() && j.extend(&points[end + 1], tol, JOIN_SPAN_UM) {
                    end += 1;
                }
                if end == start {
                    start += 1;
                    continue;
                }
                for v in start + 1..end {
                    let d = off(&points[start], &points[end], &points[v]);
                    proptest::prop_assert!(d <= tol as f64, "vertex {} is {} µm off", v, d);
                }
                start = end;
            }
        }
    }
}
