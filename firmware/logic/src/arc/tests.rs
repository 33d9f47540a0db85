use super::*;
use proptest::prelude::*;
use std::vec::Vec;

const XY: Plane = Plane {
    axis_0: 0,
    axis_1: 1,
    linear: Some(2),
};
const TOL: Milli = Milli(10);

fn sweep(start: Position, end: Position, clockwise: bool, tolerance: Milli) -> Sweep {
    Sweep {
        start,
        end,
        plane: XY,
        clockwise,
        tolerance,
    }
}

fn at(x: i32, y: i32, z: i32) -> Position {
    [Milli(x), Milli(y), Milli(z)]
}

/// Every chord end on the circle (±1 µm of rounding), every chord's middle
/// within the tolerance of it, the last end exactly `end`.
fn check(arc: Arc, start: Position, end: Position, centre: (f64, f64), r: f64) -> Vec<Position> {
    let ends: Vec<Position> = arc.collect();
    assert_eq!(*ends.last().unwrap(), end, "ends exactly on the target");
    let mut prev = start;
    for p in &ends {
        let (x, y) = (p[0].0 as f64, p[1].0 as f64);
        let d = ((x - centre.0).powi(2) + (y - centre.1).powi(2)).sqrt();
        assert!(
            (d - r).abs() <= 1.5,
            "chord end {d:.2} from the centre, radius {r}"
        );
        let (mx, my) = ((x + prev[0].0 as f64) / 2.0, (y + prev[1].0 as f64) / 2.0);
        let dm = ((mx - centre.0).powi(2) + (my - centre.1).powi(2)).sqrt();
        assert!(r - dm <= TOL.0 as f64 + 1.5, "sagitta {:.2} µm", r - dm);
        prev = *p;
    }
    ends
}

#[test]
fn quarter_circles_in_every_quadrant_and_direction() {
    // Radius 10 mm around (0,0): start on an axis, a quarter each way.
    let r = 10_000;
    let starts = [(r, 0), (0, r), (-r, 0), (0, -r)];
    for (k, &(x0, y0)) in starts.iter().enumerate() {
        for clockwise in [false, true] {
            let (x1, y1) = match clockwise {
                false => starts[(k + 1) % 4],
                true => starts[(k + 3) % 4],
            };
            let (start, end) = (at(x0, y0, 0), at(x1, y1, 0));
            let arc =
                Arc::from_centre(&sweep(start, end, clockwise, TOL), [Milli(-x0), Milli(-y0)])
                    .unwrap();
            // A quarter of 62.8 mm in chords of 2·√(10·19990) µm ≈ 0.89 mm.
            assert_eq!(arc.chords(), 18);
            check(arc, start, end, (0.0, 0.0), r as f64);
        }
    }
}

#[test]
fn a_full_circle_when_the_end_is_the_start() {
    let start = at(5_000, 0, 0);
    for clockwise in [false, true] {
        let arc = Arc::from_centre(
            &sweep(start, start, clockwise, TOL),
            [Milli(-5_000), Milli(0)],
        )
        .unwrap();
        let ends = check(arc, start, start, (0.0, 0.0), 5_000.0);
        // It goes round: through the far side.
        assert!(ends.iter().any(|p| p[0].0 < -4_900));
        let quarter = ends[ends.len() / 4];
        assert_eq!(quarter[1].0 > 0, !clockwise, "{quarter:?}");
    }
}

#[test]
fn radius_form_picks_the_centre_by_direction_and_sign() {
    let (start, end) = (at(0, 0, 0), at(10_000, 10_000, 0));
    // G2 R10: the short way round the centre (10, 0); G3 R10 round (0, 10).
    let arc = Arc::from_radius(&sweep(start, end, true, TOL), Milli(10_000)).unwrap();
    check(arc, start, end, (10_000.0, 0.0), 10_000.0);
    let arc = Arc::from_radius(&sweep(start, end, false, TOL), Milli(10_000)).unwrap();
    check(arc, start, end, (0.0, 10_000.0), 10_000.0);
    // G2 R-10: the long way (270°) round (0, 10).
    let arc = Arc::from_radius(&sweep(start, end, true, TOL), Milli(-10_000)).unwrap();
    let ends = check(arc, start, end, (0.0, 10_000.0), 10_000.0);
    assert!(ends.iter().any(|p| p[1].0 > 19_900), "over the top");
    assert_eq!(
        Arc::from_radius(&sweep(start, end, true, TOL), Milli(7_000)),
        Err(ArcError::RadiusTooSmall)
    );
}

#[test]
fn an_end_off_the_circle_is_refused_and_a_helix_climbs_evenly() {
    let start = at(10_000, 0, 0);
    let off = at(0, 10_100, 0);
    assert_eq!(
        Arc::from_centre(&sweep(start, off, false, TOL), [Milli(-10_000), Milli(0)]),
        Err(ArcError::EndOffCircle)
    );
    let end = at(0, 10_000, 4_000);
    let arc = Arc::from_centre(&sweep(start, end, false, TOL), [Milli(-10_000), Milli(0)]).unwrap();
    let n = arc.chords() as i32;
    let z: Vec<i32> = arc.map(|p| p[2].0).collect();
    for (k, z) in z.iter().enumerate() {
        assert_eq!(*z, 4_000 * (k as i32 + 1) / n);
    }
}

proptest! {
    /// Any arc in the centre form: exact end, chords within the tolerance.
    #[test]
    fn any_arc_ends_exactly_within_the_tolerance(
        cx in -50_000i32..50_000, cy in -50_000i32..50_000,
        r in 1_000i32..100_000, a0 in 0.0f64..std::f64::consts::TAU, a1 in 0.0f64..std::f64::consts::TAU,
        clockwise: bool,
    ) {
        let p = |a: f64| at(cx + (r as f64 * a.cos()).round() as i32, cy + (r as f64 * a.sin()).round() as i32, 0);
        let (start, end) = (p(a0), p(a1));
        let offset = [Milli(cx - start[0].0), Milli(cy - start[1].0)];
        let arc = Arc::from_centre(&sweep(start, end, clockwise, TOL), offset).unwrap();
        // Read in place, from the start and part-way, the ends are the
        // arc's own.
        prop_assert_eq!(arc.ends().collect::<Vec<_>>(), arc.collect::<Vec<_>>());
        let mut part_way = arc;
        let _ = part_way.nth(arc.chords() as usize / 3);
        prop_assert_eq!(part_way.ends().collect::<Vec<_>>(), part_way.collect::<Vec<_>>());
        check(arc, start, end, (cx as f64, cy as f64), r as f64);
    }
}

proptest! {
    /// The box from `bounds` holds every chord end, and is no larger than
    /// the chord ends' own box by more than the chords' sagitta.
    #[test]
    fn bounds_hold_every_chord_end_and_no_more(
        cx in -50_000i32..50_000, cy in -50_000i32..50_000,
        r in 1_000i32..100_000, a0 in -3.2f64..3.2, a1 in -3.2f64..3.2,
        clockwise: bool, tol in 1i32..200,
    ) {
        let p = |a: f64| at(cx + (r as f64 * a.cos()).round() as i32, cy + (r as f64 * a.sin()).round() as i32, 7);
        let (start, end) = (p(a0), p(a1));
        let offset = [Milli(cx - start[0].0), Milli(cy - start[1].0)];
        let arc = Arc::from_centre(&sweep(start, end, clockwise, Milli(tol)), offset).unwrap();
        let (lo, hi) = arc.bounds();
        let mut seen = (start, start);
        for q in arc.chain([start]) {
            for i in 0..AXES {
                prop_assert!(lo[i] <= q[i] && q[i] <= hi[i], "axis {} {:?} outside {:?}..{:?}", i, q[i], lo[i], hi[i]);
                seen.0[i] = seen.0[i].min(q[i]);
                seen.1[i] = seen.1[i].max(q[i]);
            }
        }
        for i in 0..AXES {
            prop_assert!(seen.0[i].0 - lo[i].0 <= tol + 2 && hi[i].0 - seen.1[i].0 <= tol + 2,
                "axis {}: box {:?}..{:?}, chord ends {:?}..{:?}", i, lo[i], hi[i], seen.0[i], seen.1[i]);
        }
    }
}

#[test]
fn a_full_circle_is_bounded_by_its_diameter() {
    let start = at(10_000, 0, 0);
    let arc =
        Arc::from_centre(&sweep(start, start, true, TOL), [Milli(-10_000), Milli(0)]).unwrap();
    let (lo, hi) = arc.bounds();
    assert_eq!((lo[0], hi[0]), (Milli(-10_000), Milli(10_000)));
    assert_eq!((lo[1], hi[1]), (Milli(-10_000), Milli(10_000)));
}
