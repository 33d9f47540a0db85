//! The image's 64-bit product, `__muldi3`, in place of libgcc's.
//!
//! Segment preparation, the planner and the executor multiply `u64`s
//! some 60 times a line, nearly always two factors below 2^32 (an event
//! count by a speed², a pace by a count). libgcc's routine is built for
//! size: ~350 cycles a call whatever the factors. This one multiplies two
//! 32-bit halves with the hardware's 8×8 `mul`, sixteen products added
//! column by column (`taut_mul32`, ~85 cycles), once when both high
//! halves are zero (~160 cycles a call in all), else three times: the low
//! halves' product plus the low halves of the two cross products, shifted
//! up 32 bits (what reaches a result taken modulo 2^64). Linked as an
//! object of every image, it is the definition the linker takes (the
//! builtins' portable one is weak, and libgcc's is not linked).
//! Checked against a product built from 16-bit pieces by
//! `examples/arith_check.rs` (HIL test
//! `harness::the_images_wide_arithmetic_is_exact`).
//!
//! The routine is `mul64.S` beside this file (assembled by `build.rs`:
//! LLVM's assembler takes module-level AVR assembly for the plainest core,
//! without `push` or `mul`).

extern "C" {
    fn __muldi3(a: u64, b: u64) -> u64;
}

/// `a · b` modulo 2^64 by `mul64.S`, called by name (the check
/// image's way to be sure which routine it tries).
pub fn mul(a: u64, b: u64) -> u64 {
    // SAFETY: `__muldi3` (mul64.S) keeps the C calling convention and touches
    // no memory but its own stack frame.
    unsafe { __muldi3(a, b) }
}
