use super::trapezoid::{cbrt_floor_approx, isqrt, per_speed};
use super::*;
use crate::axis::AXES;
use proptest::prelude::*;
use std::vec::Vec;

/// Inputs of one block's profile, feasible (entry and exit reachable).
#[derive(Clone, Copy, Debug)]
struct Ramp {
    events: u32,
    accel: u32,
    v0_sqr: u64,
    cruise_sqr: u64,
    v1_sqr: u64,
}

impl Ramp {
    fn trapezoid(&self) -> Trapezoid {
        Trapezoid::new(
            self.events,
            self.accel,
            &Speeds {
                entry_sqr: self.v0_sqr,
                cruise_sqr: self.cruise_sqr,
                exit_sqr: self.v1_sqr,
            },
        )
    }

    /// Exact time of event `k` on the continuous trapezoid, seconds.
    fn ideal(&self, k: u32) -> f64 {
        let (e, a) = (self.events as f64, self.accel as f64);
        let two_ae = 2 * self.accel as u64 * self.events as u64;
        let peak = self
            .cruise_sqr
            .min((self.v0_sqr + self.v1_sqr + two_ae) / 2)
            .max(self.v0_sqr)
            .max(self.v1_sqr) as f64;
        let (v0, v1) = (self.v0_sqr as f64, self.v1_sqr as f64);
        let (sa, sd, vp) = (
            (peak - v0) / (2.0 * a),
            (peak - v1) / (2.0 * a),
            peak.sqrt(),
        );
        let t_acc = (vp - v0.sqrt()) / a;
        let t_end = t_acc + (e - sa - sd) / vp + (vp - v1.sqrt()) / a;
        let k = k as f64;
        if k <= sa {
            ((v0 + 2.0 * a * k).sqrt() - v0.sqrt()) / a
        } else if k >= e - sd {
            t_end - ((v1 + 2.0 * a * (e - k)).sqrt() - v1.sqrt()) / a
        } else {
            t_acc + (k - sa) / vp
        }
    }
}

fn ramp() -> impl Strategy<Value = Ramp> {
    (
        1u32..20_000,
        50u32..20_000,
        0u64..1600,
        10u64..60_000,
        0u64..1600,
    )
        .prop_map(|(events, accel, v0, vc, v1)| {
            let two_ae = 2 * accel as u64 * events as u64;
            let v0_sqr = (v0 * v0).min(vc * vc);
            let v1_sqr = (v1 * v1).min(vc * vc).min(v0_sqr + two_ae);
            let v0_sqr = v0_sqr.min(v1_sqr + two_ae);
            Ramp {
                events,
                accel,
                v0_sqr,
                cruise_sqr: vc * vc,
                v1_sqr,
            }
        })
}

/// Segments and blocks of a chain of profiles, one single-axis block each.
fn prepare(ramps: &[Ramp]) -> (Vec<Segment>, Vec<StepBlock>) {
    let mut prep = Preparer::new();
    let (mut segs, mut blocks) = (Vec::new(), Vec::new());
    for r in ramps {
        prep.start(r.trapezoid());
        blocks.push(StepBlock {
            steps: [r.events, 0, 0],
            events: r.events,
            dir: 1,
        });
        while let Some(s) = prep.next_segment() {
            segs.push(s);
        }
        assert!(prep.is_idle());
    }
    (segs, blocks)
}

/// Largest distance of an event from its ideal time, ticks.
fn worst_error(ramps: &[Ramp]) -> f64 {
    let (segs, blocks) = prepare(ramps);
    let mut ideal = Vec::new();
    let mut origin = 0.0;
    for r in ramps {
        ideal.extend((1..=r.events).map(|k| origin + r.ideal(k)));
        origin += r.ideal(r.events);
    }
    let events: Vec<Event> = expand(segs, blocks).collect();
    assert_eq!(events.len(), ideal.len());
    events
        .iter()
        .zip(&ideal)
        .map(|(e, t)| (e.tick as f64 - t * TICK_HZ as f64).abs())
        .fold(0.0, f64::max)
}

#[test]
fn roots_are_exact() {
    for x in [0u64, 1, 2, 3, 4, 8, 26, 27, 1 << 40, u64::MAX] {
        let r = isqrt(x);
        assert!(r * r <= x && (r + 1).checked_mul(r + 1).is_none_or(|s| s > x));
    }
}

#[test]
fn cube_root_is_a_close_lower_bound() {
    for x in [
        1u64,
        2,
        7,
        8,
        9,
        26,
        27,
        1000,
        1 << 33,
        3 << 40,
        u64::MAX / 3,
    ] {
        let c = cbrt_floor_approx(x) as f64;
        let exact = (x as f64).cbrt();
        assert!(
            c <= exact + 1e-9 && c >= exact / 1.042 - 1.0,
            "cbrt({x}) = {c}, exact {exact}"
        );
    }
}

proptest::proptest! {
    #[test]
    fn cube_root_is_a_close_lower_bound_everywhere(x in proptest::prelude::any::<u64>()) {
        let c = cbrt_floor_approx(x) as f64;
        let exact = (x as f64).cbrt();
        proptest::prop_assert!(c <= exact * (1.0 + 1e-12) && c >= exact / 1.042 - 1.0);
    }

    #[test]
    fn isqrt_of_32_bits_is_the_floor_root(x in proptest::prelude::any::<u32>()) {
        let (r, x) = (isqrt(x as u64), x as u64);
        proptest::prop_assert!(r * r <= x && (r + 1) * (r + 1) > x);
    }

    #[test]
    fn isqrt_is_the_floor_root_at_every_length(x in proptest::prelude::any::<u64>(), k in 0u32..64) {
        // Every scale the root's top-bits path takes (random u64s are
        // nearly all 63–64 bits long), and squares' neighbours.
        let x = x >> k;
        let r = isqrt(x);
        proptest::prop_assert!(r * r <= x);
        proptest::prop_assert!((r + 1).checked_mul(r + 1).is_none_or(|s| s > x));
        let s = (x >> 32).max(1) * (x >> 32).max(1);
        for y in [s - 1, s, s + 1] {
            let r = isqrt(y);
            proptest::prop_assert!(r * r <= y && (r + 1) * (r + 1) > y);
        }
    }

    #[test]
    fn isqrt_is_the_floor_root(x in proptest::prelude::any::<u64>()) {
        let r = isqrt(x);
        proptest::prop_assert!(r * r <= x);
        proptest::prop_assert!((r + 1).checked_mul(r + 1).is_none_or(|s| s > x));
    }
}

#[test]
fn segment_is_small() {
    assert!(core::mem::size_of::<Segment>() <= 12);
    assert!(core::mem::size_of::<StepBlock>() <= 24);
}

#[test]
fn string_art_ramp_is_accurate_and_compact() {
    // Full turn of the base at the defaults: 0 → 2000 → 0 steps/s at 500/s².
    let r = Ramp {
        events: 9600,
        accel: 500,
        v0_sqr: 0,
        cruise_sqr: 2000 * 2000,
        v1_sqr: 0,
    };
    assert!(worst_error(&[r]) <= TOLERANCE_TICKS as f64);
    let (segs, _) = prepare(&[r]);
    // 469: one per event below ~400 steps/s (where `add` outgrows i16 and
    // events are ≥ 2.5 ms apart), up to 128 events per segment above.
    std::println!("segments for a 9600-step move: {}", segs.len());
    assert!(segs.len() < 9600 / 16, "{} segments", segs.len());
}

#[test]
fn fast_cruise_is_few_segments() {
    // 40 kHz for one second after a steep ramp: segments of 50 ms (a
    // hold waits for the queued ones), 2000 events each.
    let r = Ramp {
        events: 40_000,
        accel: 200_000,
        v0_sqr: 40_000 * 40_000,
        cruise_sqr: 40_000 * 40_000,
        v1_sqr: 40_000 * 40_000,
    };
    assert!(worst_error(&[r]) <= TOLERANCE_TICKS as f64);
    let (segs, _) = prepare(&[r]);
    assert!(segs.len() <= 20 + 1, "{}", segs.len());
    assert!(segs.iter().all(|s| s.duration_us() <= 50_000));
}

#[test]
fn first_step_from_standstill_waits_long() {
    // sqrt(2 / 500) s = 63.2 ms = 1.01 M ticks before the first step.
    let r = Ramp {
        events: 10,
        accel: 500,
        v0_sqr: 0,
        cruise_sqr: 1_000_000,
        v1_sqr: 0,
    };
    let (segs, blocks) = prepare(&[r]);
    let first = expand(segs, blocks).next().unwrap();
    assert!((first.tick as f64 - 0.063_245_6 * 16e6).abs() < 16.0);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn every_event_within_tolerance(r in ramp()) {
        let err = worst_error(&[r]);
        prop_assert!(err <= TOLERANCE_TICKS as f64, "error {} ticks", err);
    }

    #[test]
    fn chained_blocks_do_not_drift(a in ramp(), b in ramp()) {
        // Join b to a's exit speed so the chain is continuous.
        let two_ae = 2 * b.accel as u64 * b.events as u64;
        let b = Ramp { v0_sqr: a.v1_sqr.min(b.v1_sqr + two_ae).min(b.cruise_sqr), ..b };
        let b = Ramp { v1_sqr: b.v1_sqr.min(b.v0_sqr + two_ae), ..b };
        let err = worst_error(&[a, b, a]);
        prop_assert!(err <= TOLERANCE_TICKS as f64, "error {} ticks", err);
    }

    #[test]
    fn trapezoid_time_matches_exact(r in ramp(), f in 0.0f64..1.0) {
        let t = r.trapezoid();
        let k = (f * r.events as f64) as u32;
        let exact = r.ideal(k) * SUBTICKS_PER_S as f64;
        prop_assert!((t.time(k) as f64 - exact).abs() < 64.0 + exact * 1e-9);
    }

    #[test]
    fn narrow_division_is_exact(d in 1u32.., q in any::<u32>(), r in any::<u32>()) {
        let n = q as u64 * d as u64 + (r % d) as u64;
        prop_assert_eq!(div_to_u32(n, d), q);
    }

    /// A ramp's time by the reciprocal is the exact quotient, or up to
    /// 2 sub-ticks below it.
    #[test]
    fn ramp_time_by_reciprocal_is_within_two_subticks(
        accel in 1u32..=MAX_ACCEL,
        shift in 0u32..=32,
        ds in any::<u32>(),
    ) {
        let (m, p) = per_speed(accel, shift);
        prop_assert!(m >> 62 != 0, "{m:#x}");
        let ds = ds as u128;
        let exact = ds * SUBTICKS_PER_S as u128 / ((accel as u128) << shift);
        let by_reciprocal = (ds * m as u128) >> p;
        prop_assert!(by_reciprocal <= exact && exact - by_reciprocal <= 2);
    }

    #[test]
    fn dda_steps_exact_totals(steps in proptest::array::uniform3(0u32..3000)) {
        let events = *steps.iter().max().unwrap();
        prop_assume!(events > 0);
        let block = StepBlock { steps, events, dir: 0 };
        let seg = Segment { interval: 1000, count: events as u16, add: 0, flags: NEW_BLOCK };
        let mut totals = [0u32; AXES];
        for e in expand([seg], [block]) {
            for (i, t) in totals.iter_mut().enumerate() {
                *t += (e.axes >> i & 1) as u32;
            }
            prop_assert!(e.axes & 1 << steps.iter().position(|&s| s == events).unwrap() != 0);
        }
        prop_assert_eq!(totals, steps);
    }
}

proptest! {
    /// A profile made over the one before (the preparer's, in place,
    /// keeping what depends on the acceleration alone) is the profile
    /// made afresh.
    #[test]
    fn a_profile_made_in_place_over_another_is_made_afresh(
        events in 1u32..5000,
        accel in 1u32..20_000,
        speeds in proptest::array::uniform3(0u64..4_000_000_000),
        before in proptest::array::uniform3(0u64..4_000_000_000),
        same_accel in proptest::bool::ANY,
    ) {
        let s = |v: [u64; 3]| Speeds { entry_sqr: v[0], cruise_sqr: v[1], exit_sqr: v[2] };
        let mut t = Trapezoid::new(events / 2 + 1, if same_accel { accel } else { accel + 7 }, &s(before));
        t.begin_in_place(events, accel, &s(speeds));
        while !t.advance() {}
        prop_assert_eq!(t, Trapezoid::new(events, accel, &s(speeds)));
    }
}
