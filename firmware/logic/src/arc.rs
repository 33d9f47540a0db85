//! Arcs (`G2`/`G3`) cut into chords, as Grbl's `mc_arc` does: the centre
//! from the `I J K` offsets or from the radius `R`, the angular travel
//! (clockwise or not, a full circle when the end is the start), then
//! chords short enough that none strays more than the tolerance from the
//! circle. The chord ends come from rotating the radius vector by a fixed
//! small angle (four multiplications a chord) and, every
//! [`EXACT_EVERY`] chords, from sine and cosine, so rounding never builds
//! up; the last chord ends exactly on the target. An axis outside the
//! plane moves linearly along the arc (a helix).

use crate::axis::AXES;
use crate::fmath;
use crate::kinematics::Position;
use crate::units::Milli;
use core::f32::consts::{FRAC_PI_2, TAU};

/// Chords between exact recomputations of the rotation.
pub const EXACT_EVERY: u32 = 12;

/// An end further than this from the circle through the start is a bad
/// target (Grbl's rule, `gcode.c` line 826: over 0.005 mm and 0.1 % of
/// the radius, or over 0.5 mm).
const RADIUS_SLACK: f32 = 5.0;
const RADIUS_SLACK_REL: f32 = 0.001;
const RADIUS_SLACK_MAX: f32 = 500.0;

/// Why an arc cannot be made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArcError {
    /// The end is not on the circle through the start (centre form).
    EndOffCircle,
    /// No circle of that radius joins start and end (radius form).
    RadiusTooSmall,
}

/// The arc's plane: the indices (in a [`Position`]) of its two axes, and
/// of the axis that moves linearly along it, if any.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Plane {
    pub axis_0: usize,
    pub axis_1: usize,
    pub linear: Option<usize>,
}

/// What an arc is asked for besides its circle: its ends, plane, turn
/// (`clockwise` for `G2`) and how far its chords may stray. Passed by
/// reference: the AVR backend garbles arguments passed on the stack.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sweep {
    pub start: Position,
    pub end: Position,
    pub plane: Plane,
    pub clockwise: bool,
    pub tolerance: Milli,
}

/// An arc being cut: an iterator over its chords' end positions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Arc {
    plane: Plane,
    start: Position,
    end: Position,
    /// Centre in the plane, and the radius, milli-units.
    centre: [f32; 2],
    radius: f32,
    /// Angle of the start from the centre, and the angle each chord turns.
    start_angle: f32,
    step: f32,
    /// cos and sin of `step`.
    rotation: [f32; 2],
    /// The radius vector of the last chord end, relative to the centre.
    vector: [f32; 2],
    chords: u32,
    done: u32,
}

/// The circle an arc runs on: its centre in the plane and its radius,
/// milli-units. Worked out apart from the [`Arc`] (83 B): a caller deep
/// in the stack holds one arc, not a result and a copy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Circle {
    pub centre: [f32; 2],
    pub radius: f32,
}

impl Circle {
    /// From the centre's offsets from the start (`I J K` of the plane's
    /// axes). The end may be the start: a full circle.
    #[inline(never)]
    pub fn from_centre(sweep: &Sweep, offset: [Milli; 2]) -> Result<Circle, ArcError> {
        let Sweep {
            start, end, plane, ..
        } = *sweep;
        let (x0, y0) = (start[plane.axis_0].0 as f32, start[plane.axis_1].0 as f32);
        let centre = [x0 + offset[0].0 as f32, y0 + offset[1].0 as f32];
        let r = fmath::sqrt(sq(offset[0].0 as f32) + sq(offset[1].0 as f32));
        let (x1, y1) = (end[plane.axis_0].0 as f32, end[plane.axis_1].0 as f32);
        let r_end = fmath::sqrt(sq(x1 - centre[0]) + sq(y1 - centre[1]));
        let off = (r - r_end).abs();
        if off > RADIUS_SLACK && (off > RADIUS_SLACK_MAX || off > RADIUS_SLACK_REL * r) {
            return Err(ArcError::EndOffCircle);
        }
        Ok(Circle { centre, radius: r })
    }

    /// From the radius `R`: the shorter arc's, or the longer one's for a
    /// negative radius (Grbl's rule), `clockwise` for `G2`.
    #[inline(never)]
    pub fn from_radius(sweep: &Sweep, radius: Milli) -> Result<Circle, ArcError> {
        let Sweep {
            start,
            end,
            plane,
            clockwise,
            ..
        } = *sweep;
        let (x0, y0) = (start[plane.axis_0].0 as f32, start[plane.axis_1].0 as f32);
        let x = end[plane.axis_0].0 as f32 - x0;
        let y = end[plane.axis_1].0 as f32 - y0;
        let r = radius.0 as f32;
        let h2 = 4.0 * r * r - x * x - y * y;
        let chord = fmath::sqrt(x * x + y * y);
        if h2 < 0.0 || chord == 0.0 {
            return Err(ArcError::RadiusTooSmall);
        }
        // Signed distance of the centre from the chord's midpoint, over
        // half the chord; its sign picks the centre's side.
        let mut h = -fmath::sqrt(h2) / chord;
        if !clockwise {
            h = -h;
        }
        if r < 0.0 {
            h = -h;
        }
        let centre = [x0 + 0.5 * (x - y * h), y0 + 0.5 * (y + x * h)];
        Ok(Circle {
            centre,
            radius: r.abs(),
        })
    }
}

impl Arc {
    /// [`Circle::from_centre`]'s arc.
    pub fn from_centre(sweep: &Sweep, offset: [Milli; 2]) -> Result<Arc, ArcError> {
        Ok(Arc::new(sweep, &Circle::from_centre(sweep, offset)?))
    }

    /// [`Circle::from_radius`]'s arc.
    pub fn from_radius(sweep: &Sweep, radius: Milli) -> Result<Arc, ArcError> {
        Ok(Arc::new(sweep, &Circle::from_radius(sweep, radius)?))
    }

    /// The arc of `sweep` on `circle`, cut into chords.
    #[inline(never)]
    pub fn new(sweep: &Sweep, circle: &Circle) -> Arc {
        let Circle { centre, radius: r } = *circle;
        // The ends read where they are: a copy of them would sit in the
        // frame under the sines (the console's deepest stack).
        let (start, end) = (&sweep.start, &sweep.end);
        let (plane, clockwise, tolerance) = (sweep.plane, sweep.clockwise, sweep.tolerance);
        let v0 = [
            start[plane.axis_0].0 as f32 - centre[0],
            start[plane.axis_1].0 as f32 - centre[1],
        ];
        let v1 = [
            end[plane.axis_0].0 as f32 - centre[0],
            end[plane.axis_1].0 as f32 - centre[1],
        ];
        let mut travel = fmath::atan2(v0[0] * v1[1] - v0[1] * v1[0], v0[0] * v1[0] + v0[1] * v1[1]);
        // A turn of nothing is a full circle (the end is the start).
        const EPSILON: f32 = 5e-7;
        if clockwise && travel >= -EPSILON {
            travel -= TAU;
        } else if !clockwise && travel <= EPSILON {
            travel += TAU;
        }
        // A chord whose sagitta is the tolerance spans 2·√(t(2r − t)).
        let t = (tolerance.0.max(1) as f32).min(r);
        let half_chord = fmath::sqrt(t * (2.0 * r - t));
        // Rounded up (Grbl rounds down, and strays a little past it).
        let chords = ((0.5 * travel * r).abs() / half_chord) as u32 + 1;
        let step = travel / chords as f32;
        let (sin, cos) = fmath::sin_cos(step);
        Arc {
            plane,
            start: *start,
            end: *end,
            centre,
            radius: r,
            start_angle: fmath::atan2(v0[1], v0[0]),
            step,
            rotation: [cos, sin],
            vector: v0,
            chords,
            done: 0,
        }
    }

    /// Chords in all.
    pub fn chords(&self) -> u32 {
        self.chords
    }

    /// Chords not yet taken.
    pub fn remaining(&self) -> u32 {
        self.chords - self.done
    }

    /// Length along the circle (and the helix's axis), thousandths.
    pub fn length(&self) -> f32 {
        let turn = (self.step * self.chords as f32 * self.radius).abs();
        let rise = match self.plane.linear {
            Some(i) => (self.end[i].0 - self.start[i].0) as f32,
            None => 0.0,
        };
        fmath::sqrt(turn * turn + rise * rise)
    }

    pub fn start(&self) -> Position {
        self.start
    }

    /// The smallest box (least and greatest corner) holding every chord
    /// end: both ends, and the circle's extremes the arc passes. Chords
    /// lie inside the circle, so the box holds the whole path: checked
    /// against the travel before anything moves.
    #[inline(never)]
    pub fn bounds(&self) -> (Position, Position) {
        let mut lo = self.start;
        let mut hi = self.start;
        for i in 0..AXES {
            lo[i] = lo[i].min(self.end[i]);
            hi[i] = hi[i].max(self.end[i]);
        }
        let travel = self.step * self.chords as f32;
        let (from, to) = if travel < 0.0 {
            (self.start_angle + travel, self.start_angle)
        } else {
            (self.start_angle, self.start_angle + travel)
        };
        // Each quarter turn k·π/2 the arc sweeps is an extreme: +axis_0,
        // +axis_1, −axis_0, −axis_1 in turn. Rounded as a chord end is,
        // with just under half a µm of slack for the rotation's error (a chord end
        // rounded up past a radius a little under its half µm).
        let mut k = (from / FRAC_PI_2) as i32 - 1;
        while k as f32 * FRAC_PI_2 <= to {
            if k as f32 * FRAC_PI_2 >= from {
                let (i, sign) = match k.rem_euclid(4) {
                    0 => (0, 1.0),
                    1 => (1, 1.0),
                    2 => (0, -1.0),
                    _ => (1, -1.0),
                };
                let axis = if i == 0 {
                    self.plane.axis_0
                } else {
                    self.plane.axis_1
                };
                let extreme = Milli(round(self.centre[i] + sign * (self.radius + 0.49)));
                lo[axis] = lo[axis].min(extreme);
                hi[axis] = hi[axis].max(extreme);
            }
            k += 1;
        }
        (lo, hi)
    }
}

impl Iterator for Arc {
    type Item = Position;

    /// The next chord's end.
    fn next(&mut self) -> Option<Position> {
        let (mut done, mut vector) = (self.done, self.vector);
        let end = self.end_after(&mut done, &mut vector);
        (self.done, self.vector) = (done, vector);
        end
    }
}

impl Arc {
    /// The chord ends still to come, without a copy of the arc (83 B): the
    /// reach check walks them deep in the stack.
    pub fn ends(&self) -> Ends<'_> {
        Ends {
            arc: self,
            done: self.done,
            vector: self.vector,
        }
    }

    /// The end of chord `done + 1`, `done` and the radius vector taken on
    /// to it; `None` past the last.
    fn end_after(&self, done: &mut u32, vector: &mut [f32; 2]) -> Option<Position> {
        if *done >= self.chords {
            return None;
        }
        *done += 1;
        if *done == self.chords {
            return Some(self.end);
        }
        let k = *done;
        if k.is_multiple_of(EXACT_EVERY) {
            let (sin, cos) = fmath::sin_cos(self.start_angle + k as f32 * self.step);
            *vector = [self.radius * cos, self.radius * sin];
        } else {
            let [c, s] = self.rotation;
            let [x, y] = *vector;
            *vector = [x * c - y * s, x * s + y * c];
        }
        let p = &self.plane;
        let mut at: Position = self.start;
        at[p.axis_0] = Milli(round(self.centre[0] + vector[0]));
        at[p.axis_1] = Milli(round(self.centre[1] + vector[1]));
        if let Some(l) = p.linear {
            let span = self.end[l].0 as i64 - self.start[l].0 as i64;
            at[l] = Milli(self.start[l].0 + (span * k as i64 / self.chords as i64) as i32);
        }
        for (i, (a, e)) in at.iter_mut().zip(&self.end).enumerate() {
            if i != p.axis_0 && i != p.axis_1 && Some(i) != p.linear {
                *a = *e;
            }
        }
        Some(at)
    }
}

/// An arc's chord ends, read from the arc in place ([`Arc::ends`]): the
/// same as the arc's own iteration.
pub struct Ends<'a> {
    arc: &'a Arc,
    done: u32,
    vector: [f32; 2],
}

impl Iterator for Ends<'_> {
    type Item = Position;

    fn next(&mut self) -> Option<Position> {
        self.arc.end_after(&mut self.done, &mut self.vector)
    }
}

fn sq(x: f32) -> f32 {
    x * x
}

fn round(x: f32) -> i32 {
    if x >= 0.0 {
        (x + 0.5) as i32
    } else {
        (x - 0.5) as i32
    }
}

#[cfg(test)]
mod tests;
