//! The ideal velocity profile of one block, in events, and the exact time
//! of every event on it. Integer only: speeds are handled as fixed-point
//! square roots so a ramp's event times are `(v(k) - v0) / a`, with no
//! cancellation and no u128.

use super::SUBTICKS_PER_S as Q;

/// Part of a block's profile, by the slope of its speed: rising, flat, falling.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slope {
    Accel,
    Cruise,
    Decel,
}

/// Entry, peak and exit speed of a block with constant acceleration
/// between them. Speeds are squared, events²/s²; acceleration events/s².
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Trapezoid {
    events: u32,
    accel: u64,
    two_a: u64,
    v0_sqr: u64,
    v1_sqr: u64,
    /// The cruise speed² asked for (the peak may stay below it).
    cruise_sqr: u64,
    /// Fixed-point shift: speeds are `isqrt(v² << 2·shift)`, i.e. `v·2^shift`.
    shift: u32,
    /// `Q / (accel·2^shift)` as `per_speed / 2^per_speed_shift`: sub-ticks
    /// per unit of scaled speed, so a ramp's time is a multiplication (a
    /// `u64` division costs ~3 000 cycles on the AVR).
    per_speed: u64,
    per_speed_shift: u32,
    /// `Q / accel` rounded down: sub-ticks to stop per event/s of speed.
    stop_per_speed: u32,
    /// The part [`Trapezoid::advance`] makes next; 0 when whole.
    part: u8,
    s0: u64,
    s1: u64,
    /// Length of the ramps in units of `1 / (2a)` events.
    acc2: u64,
    dec2: u64,
    /// Cruise interval in sub-ticks `<< (31 - shift)`.
    cruise_iv: u64,
    t_acc: u64,
    t_dec: u64,
    t_end: u64,
    /// Last event fully inside the acceleration; first fully in deceleration.
    k_acc: u32,
    k_dec: u32,
}

impl Trapezoid {
    /// No events: the preparer's idle state. Built at run time: a
    /// constant this size would be copied from a template that the AVR
    /// keeps in SRAM (120 bytes); this is a clear and two stores.
    pub fn idle() -> Trapezoid {
        let one = core::hint::black_box(1);
        Trapezoid {
            events: 0,
            accel: one,
            two_a: 2 * one,
            v0_sqr: 0,
            v1_sqr: 0,
            cruise_sqr: 0,
            shift: 0,
            per_speed: 0,
            per_speed_shift: 32,
            stop_per_speed: 0,
            part: 0,
            s0: 0,
            s1: 0,
            acc2: 0,
            dec2: 0,
            cruise_iv: 0,
            t_acc: 0,
            t_dec: 0,
            t_end: 0,
            k_acc: 0,
            k_dec: 0,
        }
    }

    /// [`Trapezoid::idle`] in place. Out of line: any copy it makes is on
    /// its own frame, which calls nothing.
    #[inline(never)]
    pub fn make_idle(&mut self) {
        *self = Trapezoid::idle();
    }
}

/// Speeds² of a profile, events²/s²: where it starts, the most it may
/// reach, where it ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Speeds {
    pub entry_sqr: u64,
    pub cruise_sqr: u64,
    pub exit_sqr: u64,
}

/// Largest acceleration in events/s² the fixed-point arithmetic allows.
pub const MAX_ACCEL: u32 = 1 << 24;

impl Trapezoid {
    /// The fastest profile over `events` events that starts at the entry
    /// speed, never exceeds the cruise speed and ends at the exit speed.
    /// Entry and exit are clamped to what `accel` allows over the block
    /// (the planner already guarantees this up to rounding).
    ///
    /// The speeds come by reference: on the AVR, arguments beyond 18 bytes
    /// go on the stack, and the compiler passes stacked `u64`s wrongly
    /// (seen here: the cruise speed arrived as garbage once this function
    /// stopped being inlined). Built for speed: once a block, and built for
    /// size its frame is 130 bytes deeper (the stack peak is the motion
    /// task's cut of a segment).
    #[cfg_attr(target_arch = "avr", optimize(speed))]
    pub fn new(events: u32, accel: u32, speeds: &Speeds) -> Self {
        let mut t = Self::begin(events, accel, speeds);
        while !t.advance() {}
        t
    }

    /// [`Trapezoid::new`] in parts that each cost at most ~13 000 cycles
    /// on the AVR (a whole one ~30 000: three 64-bit roots and several
    /// divisions), so the task that makes it keeps its runs short: this
    /// is the first part (the speeds clamped, the scale chosen), then
    /// [`Trapezoid::advance`] until it returns true. Until then the
    /// profile must not be read.
    pub fn begin(events: u32, accel: u32, speeds: &Speeds) -> Self {
        let mut t = Self::idle();
        t.begin_in_place(events, accel, speeds);
        t
    }

    /// [`Trapezoid::begin`] over this profile, every field written in
    /// place: no copy of a profile (130 bytes) on the stack, where a feed
    /// hold's legs are made deep in a card print's line.
    pub fn begin_in_place(&mut self, events: u32, accel: u32, speeds: &Speeds) {
        let Speeds {
            entry_sqr,
            cruise_sqr,
            exit_sqr,
        } = *speeds;
        let a = accel.clamp(1, MAX_ACCEL) as u64;
        let two_a = 2 * a;
        let two_ae = two_a * events as u64;
        let v1_sqr = exit_sqr.min(entry_sqr.saturating_add(two_ae));
        let v0_sqr = entry_sqr.min(v1_sqr + two_ae);
        let peak = cruise_sqr
            .max(1)
            .min((v0_sqr + v1_sqr + two_ae) / 2)
            .max(v0_sqr)
            .max(v1_sqr);
        let shift = (64 - (64 - peak.leading_zeros())) / 2;
        // `per_speed` depends on the acceleration alone, its shift also
        // on the scale: kept from the block before when the acceleration
        // is the same (a `u64` division less a block); 0 asks for it.
        if self.accel == a && self.per_speed != 0 {
            self.per_speed_shift = self.per_speed_shift - self.shift + shift;
        } else {
            self.per_speed = 0;
        }
        // Entering at the speed the profile before (whole, same scale)
        // left at: its exit root is this entry's (a root less a block in
        // a stream of short ramps). Part 5 is part 1 with `s0` known.
        let entry_known = self.part == 0 && v0_sqr == self.v1_sqr && shift == self.shift;
        if entry_known {
            self.s0 = self.s1;
        }
        self.events = events;
        self.accel = a;
        self.two_a = two_a;
        self.v0_sqr = v0_sqr;
        self.v1_sqr = v1_sqr;
        self.cruise_sqr = cruise_sqr;
        self.shift = shift;
        self.acc2 = peak - v0_sqr;
        self.dec2 = peak - v1_sqr;
        // The rest is made by `advance`, in order.
        self.part = if entry_known { 5 } else { 1 };
    }

    /// The next part of the profile begun by [`Trapezoid::begin`]; true
    /// once it is whole (and for every profile after).
    #[inline(never)]
    pub fn advance(&mut self) -> bool {
        let two_ae = self.two_a * self.events as u64;
        match self.part {
            0 => return true,
            // The roots (~6 000 cycles each on the AVR), two parts: three
            // in one kept a ready task waiting ~19 000 cycles. The
            // peak's scaled speed waits in `cruise_iv`.
            // A block that cruises through (a stream of short moves at
            // speed) has one root, not three.
            part @ (1 | 5) => {
                self.cruise_iv = self.scaled_speed(self.v0_sqr + self.acc2);
                if self.acc2 == 0 {
                    self.s0 = self.cruise_iv;
                } else if part == 1 {
                    self.s0 = self.scaled_speed(self.v0_sqr);
                }
                self.part = 1;
            }
            2 => {
                self.s1 = if self.dec2 == 0 {
                    self.cruise_iv
                } else if self.v1_sqr == self.v0_sqr {
                    self.s0
                } else {
                    self.scaled_speed(self.v1_sqr)
                }
            }
            3 => {
                let sp = self.cruise_iv;
                if self.per_speed == 0 {
                    (self.per_speed, self.per_speed_shift) =
                        per_speed(self.accel as u32, self.shift);
                }
                let (per_speed, per_speed_shift) = (self.per_speed, self.per_speed_shift);
                // Q / a = per_speed / 2^(per_speed_shift - shift), below 2^33.
                self.stop_per_speed =
                    shr(per_speed, per_speed_shift - self.shift).min(u32::MAX as u64) as u32;
                // sp in [2^31, 2^32) (the scale fills 64 bits with the
                // peak²) and Q < 2^33: a 32-bit quotient, nearly always.
                self.cruise_iv = div_rem_u32(Q << 31, sp as u32).0;
                self.t_acc = self.ramp_time(sp, self.s0);
                // The peak's scaled speed until the last part.
                self.t_end = sp;
            }
            _ => {
                let sp = self.t_end;
                self.t_dec = self.t_acc + self.cruise_time(two_ae - self.acc2 - self.dec2);
                self.t_end = self.t_dec + self.ramp_time(sp, self.s1);
                // Quotients below `events`, by `2a` < 2^26: 32-bit
                // divisions, none for a block without that ramp.
                self.k_acc = match self.acc2 {
                    0 => 0,
                    acc2 => div_to_u32(acc2, self.two_a as u32),
                };
                self.k_dec = match self.dec2 {
                    0 => self.events,
                    dec2 => self.events - div_to_u32(dec2 + self.two_a - 1, self.two_a as u32),
                };
                self.part = 0;
                return true;
            }
        }
        self.part += 1;
        false
    }

    /// Every part made ([`Trapezoid::advance`]).
    pub fn is_whole(&self) -> bool {
        self.part == 0
    }

    pub fn events(&self) -> u32 {
        self.events
    }

    /// Acceleration, events/s².
    pub fn accel(&self) -> u32 {
        self.accel as u32
    }

    /// The cruise speed² asked for, events²/s².
    pub fn cruise_sqr(&self) -> u64 {
        self.cruise_sqr
    }

    /// Cruise events that fit in `subticks` (at least one): a 32-bit
    /// quotient by the interval rounded up (a `u64` division, ~3 000
    /// cycles on the AVR, once a cruise segment kept a ready console
    /// waiting).
    pub fn cruise_events_in(&self, subticks: u32) -> u32 {
        let pace = shr(self.cruise_iv, 31 - self.shift).min(u32::MAX as u64 - 1) as u32 + 1;
        div_to_u32(subticks as u64, pace).max(1)
    }

    /// Speed² at the last event, events²/s².
    pub fn exit_sqr(&self) -> u64 {
        self.v1_sqr
    }

    /// Speed² at event `k` (0..=events), events²/s².
    pub fn speed_sqr(&self, k: u32) -> u64 {
        let x = self.two_a * k as u64;
        let y = self.two_a * (self.events - k) as u64;
        if x <= self.acc2 {
            self.v0_sqr + x
        } else if y <= self.dec2 {
            self.v1_sqr + y
        } else {
            self.v0_sqr + self.acc2
        }
    }

    /// Ideal time of event `k` (0..=events), sub-ticks after event 0.
    pub fn time(&self, k: u32) -> u64 {
        self.timed(k, false).0
    }

    /// [`Trapezoid::time`] and the time per event there (`1 / v`,
    /// sub-ticks; `u32::MAX` at standstill): the speed's root gives both,
    /// for one more narrow division.
    pub fn time_and_pace(&self, k: u32) -> (u64, u32) {
        self.timed(k, true)
    }

    #[cfg_attr(target_arch = "avr", optimize(speed))]
    fn timed(&self, k: u32, pace: bool) -> (u64, u32) {
        let x = self.two_a * k as u64;
        let y = self.two_a * (self.events - k) as u64;
        let (t, s) = if k == self.events {
            (self.t_end, self.s1)
        } else if x <= self.acc2 {
            let s = self.scaled_speed(self.v0_sqr + x);
            (self.ramp_time(s, self.s0), s)
        } else if y <= self.dec2 {
            let s = self.scaled_speed(self.v1_sqr + y);
            let back = self.ramp_time(s, self.s1);
            (self.t_end.saturating_sub(back), s)
        } else {
            let t = self.t_acc + self.cruise_time_to(k);
            let iv = shr(self.cruise_iv, 31 - self.shift);
            return (t, iv.min(u32::MAX as u64) as u32);
        };
        (t, if pace { self.pace(s) } else { 0 })
    }

    /// Sub-ticks per event at scaled speed `s`: `Q·2^shift / s` (below
    /// 2^63: the shift is at most 31), saturating.
    fn pace(&self, s: u64) -> u32 {
        let n = shl(Q, self.shift);
        if s == 0 || n >> 32 >= s {
            return u32::MAX;
        }
        div_to_u32(n, s as u32)
    }

    /// The phase that holds the whole step from event `k0` to `k0 + 1`, and
    /// the last event of that phase; `None` if a phase boundary falls
    /// strictly inside the step.
    pub fn slope_after(&self, k0: u32) -> Option<(Slope, u32)> {
        if k0 < self.k_acc {
            return Some((Slope::Accel, self.k_acc));
        }
        let past_accel = k0 > self.k_acc || self.two_a * self.k_acc as u64 == self.acc2;
        if past_accel && k0 < self.k_dec {
            return Some((Slope::Cruise, self.k_dec));
        }
        if self.two_a * (self.events - k0) as u64 <= self.dec2 {
            return Some((Slope::Decel, self.events));
        }
        None
    }

    /// Speed at event `k` of a ramp, for sizing a segment: (time to stop
    /// from it at `accel`, sub-ticks; speed, events/s), both rounded down
    /// and at most 2^-14 below the exact figures: a 32-bit root of the
    /// speed²'s top bits and one product (a segment's size needs no more;
    /// the exact root and the variable 64-bit shifts of [`Trapezoid::time`]
    /// cost several times as much on the AVR).
    pub fn ramp_speed(&self, k: u32) -> (u64, u32) {
        let x = self.two_a * k as u64;
        let mut v_sqr = if x <= self.acc2 {
            self.v0_sqr + x
        } else {
            self.v1_sqr + self.two_a * (self.events - k) as u64
        };
        // Two bits at a time (constant shifts: no loop over the bytes).
        let mut half = 0;
        while v_sqr >> 32 != 0 {
            v_sqr >>= 2;
            half += 1;
        }
        let v = isqrt32(v_sqr as u32) << half;
        (v as u64 * self.stop_per_speed as u64, v)
    }

    fn scaled_speed(&self, v_sqr: u64) -> u64 {
        isqrt(shl(v_sqr, 2 * self.shift))
    }

    /// Time to change speed between two scaled speeds at `accel`: the
    /// difference (below 2^32: the scale keeps the peak's below 2^64) times
    /// `per_speed`, a 96-bit product cut to its top bits. Always inlined:
    /// called, its second `u64` would go on the stack, which the AVR
    /// backend passes wrongly (it was garbage once this stopped being
    /// inlined).
    #[inline(always)]
    fn ramp_time(&self, s_hi: u64, s_lo: u64) -> u64 {
        let ds = s_hi - s_lo;
        let low = ds * (self.per_speed & 0xFFFF_FFFF);
        let high = ds * (self.per_speed >> 32);
        shr(high + (low >> 32), self.per_speed_shift - 32)
    }

    /// [`Trapezoid::cruise_time`] from the end of the acceleration to
    /// event `k` of the cruise, without its divisions: `2a·k − acc2` is
    /// `2a·(k − k_acc) − ρ` with `ρ = acc2 − 2a·k_acc` below `2a`.
    fn cruise_time_to(&self, k: u32) -> u64 {
        let rho = self.acc2 - self.two_a * self.k_acc as u64;
        match rho {
            0 => self.cruise_span((k - self.k_acc) as u64, 0),
            _ => self.cruise_span((k - self.k_acc - 1) as u64, self.two_a - rho),
        }
    }

    /// Time to cruise `w / (2a)` events (`2a` below 2^26).
    fn cruise_time(&self, w: u64) -> u64 {
        let (q, r) = div_rem_u32(w, self.two_a as u32);
        self.cruise_span(q, r)
    }

    /// Time to cruise `q + r / (2a)` events (`r` below `2a`): the
    /// fraction's quotient fits 32 bits when the interval does (a `u64`
    /// division is ~3 000 cycles on the AVR). Always inlined: called, its
    /// arguments and result take 20 bytes, past the 18 of registers, and
    /// LLVM's AVR back end reads stack arguments one byte off on the
    /// ATmega2560, whose calls push a 3-byte return address (the cruise
    /// then ran at 54 000 steps/s).
    #[inline(always)]
    fn cruise_span(&self, q: u64, r: u64) -> u64 {
        let part = r * self.cruise_iv;
        let frac = match self.two_a as u32 {
            d if part >> 32 < d as u64 => div_to_u32(part, d) as u64,
            _ => part / self.two_a,
        };
        shr(q * self.cruise_iv + frac, 31 - self.shift)
    }
}

/// `Q / (accel·2^shift)` as `(m, p)` with `m / 2^p` (floor) and `m` in
/// [2^62, 2^64): 62 good bits, so a ramp's time is within 2 sub-ticks of
/// the exact quotient. `Q = 125 000·2^15`: one `u64 / u32` division and
/// one of the remainder, once per trapezoid.
pub(super) fn per_speed(accel: u32, shift: u32) -> (u64, u32) {
    let n = 125_000u64 << 46;
    let (q, r) = (n / accel as u64, n % accel as u64);
    // q < 2^63 and r < accel ≤ 2^24: r's next z bits fit.
    let z = q.leading_zeros();
    let m = (q << z) | ((r << z) / accel as u64);
    // m / 2^p = 125 000·2^(46+z) / (accel·2^(15+p-shift)) = Q / (accel·2^shift)
    (m, 31 + z + shift)
}

/// Integer square root, rounded down. Written for the AVR, where `u64`
/// arithmetic is a library call: a 32-bit digit-by-digit root of the top
/// half gives 16 good bits, one Newton step doubles them. Newton from
/// above never lands below the floor root, so at most a step down is
/// left to check. The step's division has a 32-bit quotient: done 32 bits
/// wide ([`div_to_u32`]), a fifth of a general `u64` division.
#[cfg_attr(target_arch = "avr", optimize(speed))]
pub fn isqrt(x: u64) -> u64 {
    if x <= u32::MAX as u64 {
        return isqrt32(x as u32) as u64;
    }
    // The largest root there is: its square and above.
    const TOP: u64 = u32::MAX as u64;
    if x >= TOP * TOP {
        return TOP;
    }
    // x ≥ 2^32: its top 31–32 bits, `x >> shift` for the even shift
    // that leaves them, from the 32-bit halves (a `u64` shift by a
    // variable is a loop of ~12 cycles a bit on the AVR, a `u32` one ~6).
    let hi = (x >> 32) as u32;
    let shift = (33 - hi.leading_zeros()) & !1;
    let top = match shift {
        32 => hi,
        s => hi << (32 - s) | (x as u32) >> s,
    };
    // r0 ≤ √x < r0 + 2^(shift/2): start from the upper end, below 2^32
    // (a root of 2^32 would need x ≥ TOP²).
    let r0 = shl(isqrt32(top) as u64 + 1, shift / 2).min(TOP) as u32;
    // x / r0 ≤ √x < 2^32: the quotient fits.
    let mut r = (r0 as u64 + div_to_u32(x, r0) as u64) / 2;
    while r * r > x {
        r -= 1;
    }
    r
}

/// `n / d` and `n % d`, 32 bits wide ([`div_to_u32`], a fifth of a `u64`
/// division's cycles on the AVR) when the quotient fits.
fn div_rem_u32(n: u64, d: u32) -> (u64, u64) {
    if n >> 32 < d as u64 {
        let q = div_to_u32(n, d) as u64;
        (q, n - q * d as u64)
    } else {
        (n / d as u64, n % d as u64)
    }
}

/// `x << n` for `n < 64`: whole bytes, then bits. On the AVR a variable
/// `u64` shift is a loop of one-bit shifts over eight bytes (~12 cycles a
/// bit); a constant shift by whole bytes is register moves, so the bytes
/// go by a `match` (~70 cycles in all, where copying through a byte
/// array took ~250).
fn shl(x: u64, n: u32) -> u64 {
    let x = match n / 8 {
        0 => x,
        1 => x << 8,
        2 => x << 16,
        3 => x << 24,
        4 => x << 32,
        5 => x << 40,
        6 => x << 48,
        _ => x << 56,
    };
    x << (n % 8)
}

/// `x >> n` for `n < 64`, as [`shl`]: whole bytes by a `match`, then bits.
fn shr(x: u64, n: u32) -> u64 {
    let x = match n / 8 {
        0 => x,
        1 => x >> 8,
        2 => x >> 16,
        3 => x >> 24,
        4 => x >> 32,
        5 => x >> 40,
        6 => x >> 48,
        _ => x >> 56,
    };
    x >> (n % 8)
}

/// `n / d`, for a quotient known to fit 32 bits (`n >> 32 < d`): restoring
/// division a bit at a time, on 32-bit halves.
#[cfg(not(target_arch = "avr"))]
pub fn div_to_u32(n: u64, d: u32) -> u32 {
    let mut rem = (n >> 32) as u32;
    let mut low = n as u32;
    let mut q = 0u32;
    for _ in 0..32 {
        // rem < d: shifted in, it may need a 33rd bit (`carry`).
        let carry = rem >> 31;
        rem = rem << 1 | low >> 31;
        low <<= 1;
        q <<= 1;
        if carry != 0 || rem >= d {
            rem = rem.wrapping_sub(d);
            q |= 1;
        }
    }
    q
}

/// The same on the AVR, in assembly (the compiled loop spilled to the
/// stack: 2 300 cycles): the dividend's low half shifts into the
/// remainder while the quotient's bits fill it from the right, ~20 cycles
/// a bit. Leading zero bytes of the quotient go first, a byte at a time
/// (~19 cycles each, where eight bits take ~160): while the remainder
/// with the next dividend byte is below the divisor, that byte moves in
/// whole and the quotient gets eight zeros (a pace, a segment's `add`
/// and `interval`, a ramp's run: quotients of 8 to 24 bits). Checked
/// against the division above by `arith_check.elf` (HIL test).
#[cfg(target_arch = "avr")]
#[allow(unsafe_code)]
pub fn div_to_u32(n: u64, d: u32) -> u32 {
    let [mut l0, mut l1, mut l2, mut l3, mut r0, mut r1, mut r2, mut r3] = n.to_le_bytes();
    let [d0, d1, d2, d3] = d.to_le_bytes();
    // SAFETY: registers only; no memory, no stack.
    unsafe {
        core::arch::asm!(
            "ldi {count}, 32",
            // r3 zero and r2:r1:r0:l3 below d: eight zero bits.
            "0:",
            "tst {r3}",
            "brne 1f",
            "cp {l3}, {d0}", "cpc {r0}, {d1}", "cpc {r1}, {d2}", "cpc {r2}, {d3}",
            "brcc 1f",
            "mov {r3}, {r2}", "mov {r2}, {r1}", "mov {r1}, {r0}", "mov {r0}, {l3}",
            "mov {l3}, {l2}", "mov {l2}, {l1}", "mov {l1}, {l0}", "clr {l0}",
            "subi {count}, 8",
            "brne 0b",
            "rjmp 4f",
            "1:",
            "lsl {l0}", "rol {l1}", "rol {l2}", "rol {l3}",
            "rol {r0}", "rol {r1}", "rol {r2}", "rol {r3}",
            // A 33rd bit: above any divisor.
            "brcs 2f",
            "cp {r0}, {d0}", "cpc {r1}, {d1}", "cpc {r2}, {d2}", "cpc {r3}, {d3}",
            "brcs 3f",
            "2:",
            "sub {r0}, {d0}", "sbc {r1}, {d1}", "sbc {r2}, {d2}", "sbc {r3}, {d3}",
            // The shift left bit 0 clear: this sets the quotient's bit.
            "inc {l0}",
            "3:",
            "dec {count}",
            "brne 1b",
            "4:",
            count = out(reg_upper) _,
            l0 = inout(reg) l0, l1 = inout(reg) l1, l2 = inout(reg) l2, l3 = inout(reg) l3,
            r0 = inout(reg) r0, r1 = inout(reg) r1, r2 = inout(reg) r2, r3 = inout(reg) r3,
            d0 = in(reg) d0, d1 = in(reg) d1, d2 = in(reg) d2, d3 = in(reg) d3,
            options(pure, nomem, nostack),
        );
    }
    let _ = (r0, r1, r2, r3);
    u32::from_le_bytes([l0, l1, l2, l3])
}

/// 32-bit integer square root, rounded down (digit by digit: two bits of
/// `x` in, one bit of the root out, sixteen times).
#[cfg(not(target_arch = "avr"))]
pub fn isqrt32(mut x: u32) -> u32 {
    let (mut rem, mut root) = (0u32, 0u32);
    for _ in 0..16 {
        rem = rem << 2 | x >> 30;
        x <<= 2;
        // (2·root + 1)² − (2·root)² = 4·root + 1.
        let trial = root << 2 | 1;
        root <<= 1;
        if rem >= trial {
            rem -= trial;
            root |= 1;
        }
    }
    root
}

/// The same on the AVR, in assembly (~600 cycles; the compiled 32-bit
/// version took ~1 000): the remainder stays below 2^19 and the trial
/// below 2^17, three bytes each. Checked against the property of a floor
/// root by `segment_cycles.elf`.
#[cfg(target_arch = "avr")]
#[allow(unsafe_code)]
pub fn isqrt32(x: u32) -> u32 {
    let [mut x0, mut x1, mut x2, mut x3] = x.to_le_bytes();
    let (mut y0, mut y1) = (0u8, 0u8);
    // SAFETY: registers only; no memory, no stack.
    unsafe {
        core::arch::asm!(
            "clr {r0}", "clr {r1}", "clr {r2}",
            "ldi {count}, 16",
            "1:",
            // Two bits of x into the remainder.
            "lsl {x0}", "rol {x1}", "rol {x2}", "rol {x3}",
            "rol {r0}", "rol {r1}", "rol {r2}",
            "lsl {x0}", "rol {x1}", "rol {x2}", "rol {x3}",
            "rol {r0}", "rol {r1}", "rol {r2}",
            // trial = 4·root + 1 (bit 0 clear after the shifts).
            "mov {t0}, {y0}", "mov {t1}, {y1}", "clr {t2}",
            "lsl {t0}", "rol {t1}", "rol {t2}",
            "lsl {t0}", "rol {t1}", "rol {t2}",
            "inc {t0}",
            "lsl {y0}", "rol {y1}",
            "cp {r0}, {t0}", "cpc {r1}, {t1}", "cpc {r2}, {t2}",
            "brcs 2f",
            "sub {r0}, {t0}", "sbc {r1}, {t1}", "sbc {r2}, {t2}",
            // Bit 0 clear after the shift: this sets the root's bit.
            "inc {y0}",
            "2:",
            "dec {count}",
            "brne 1b",
            count = out(reg_upper) _,
            x0 = inout(reg) x0, x1 = inout(reg) x1, x2 = inout(reg) x2, x3 = inout(reg) x3,
            y0 = inout(reg) y0, y1 = inout(reg) y1,
            r0 = out(reg) _, r1 = out(reg) _, r2 = out(reg) _,
            t0 = out(reg) _, t1 = out(reg) _, t2 = out(reg) _,
            options(pure, nomem, nostack),
        );
    }
    let _ = (x0, x1, x2, x3);
    u16::from_le_bytes([y0, y1]) as u32
}

/// A cube root that is never above the true one and at most 4.2 % below it
/// (a power of two times the floor of `∛(2^r·(1 + f/8))`, `r` the
/// exponent's remainder by three and `f` the three bits after the leading
/// one): enough to size a segment, whose length goes with its square
/// (with 1, ∛2 and ∛4 only, up to 26 % below, ramp segments were 16 %
/// more). Byte moves and 16- or 32-bit shifts only: a variable `u64`
/// shift is a loop over eight bytes on the AVR.
pub fn cbrt_floor_approx(x: u64) -> u64 {
    if x == 0 {
        return 0;
    }
    let lz = x.leading_zeros();
    let bits = 63 - lz; // 2^bits ≤ x
    let be = x.to_be_bytes();
    let at = (lz / 8) as usize;
    let pair = u16::from_be_bytes([be[at], if at < 7 { be[at + 1] } else { 0 }]);
    let eighths = ((pair << (lz % 8)) >> 12) as usize & 7;
    let mantissa = CBRT_MANTISSA.get((bits % 3) as usize * 8 + eighths) as u32;
    let third = bits / 3;
    let c = if third >= 10 {
        mantissa << (third - 10)
    } else {
        mantissa >> (10 - third)
    };
    c as u64
}

/// `⌊1024·∛(2^r·(8 + f)/8)⌋` at `r·8 + f`, in flash on the AVR.
const CBRT_MANTISSA: taut_progmem::Table<u16> = taut_progmem::table!(u16; 24; cbrt_mantissas());

const fn cbrt_mantissas() -> [u16; 24] {
    let mut out = [0u16; 24];
    let mut i = 0;
    while i < 24 {
        // 1024³·2^r·(8 + f)/8 = 2^(27 + r)·(8 + f).
        let x = (8 + (i % 8) as u64) << (27 + i / 8);
        // The floor root by bisection: (lo+1)³ > x ≥ lo³.
        let (mut lo, mut hi) = (0u64, 2048u64);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if mid * mid * mid <= x {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        out[i] = lo as u16;
        i += 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{Speeds, Trapezoid};

    /// A block entering at the speed the one before left at takes that
    /// exit's root (no root worked out for it) and is the same profile as
    /// one made afresh; one entering at another speed works its root out.
    #[test]
    fn an_entry_at_the_last_exit_takes_its_root() {
        let speeds = |entry: u64, exit: u64| Speeds {
            entry_sqr: entry * entry,
            cruise_sqr: 900 * 900,
            exit_sqr: exit * exit,
        };
        for (entry, known) in [(400, true), (401, false)] {
            let mut t = Trapezoid::new(40, 5000, &speeds(300, 400));
            t.begin_in_place(37, 5000, &speeds(entry, 350));
            assert_eq!(t.part == 5, known, "entry {entry}");
            while !t.advance() {}
            assert_eq!(t, Trapezoid::new(37, 5000, &speeds(entry, 350)));
        }
    }
}
