//! Nestable interrupt entry for every handler except the step timer's.
//!
//! AVR has no interrupt priorities: a running handler blocks all others
//! until it returns, so a 200-cycle UART handler would delay a step pulse by
//! 12 µs. These naked trampolines take the vector, switch off their own
//! interrupt source where the flag would re-trigger (UART), re-enable
//! interrupts and jump to the real handler: the step interrupt can then
//! preempt it within ~10 cycles. The handler switches its source back on.

/// `__vector_N` → `sei; jmp handler`, for sources whose flag is cleared by
/// taking the vector (timer compare).
#[macro_export]
macro_rules! nested_vector {
    ($vector:ident, $handler:path) => {
        // SAFETY: only the vector table jumps here; the body changes no
        // register and ends in the handler, which returns with `reti`.
        #[unsafe(naked)]
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $vector() {
            core::arch::naked_asm!("sei", "jmp {h}", h = sym $handler);
        }
    };
    // Sources whose flag stays set (UART): AND the control register at data
    // address `reg` with `keep` (its enable bit cleared) first, preserving
    // r24 and SREG.
    ($vector:ident, $handler:path, reg = $reg:literal, keep = $keep:literal) => {
        // SAFETY: only the vector table jumps here; r24 and SREG are
        // restored before the jump to the handler, which returns with `reti`.
        #[unsafe(naked)]
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $vector() {
            core::arch::naked_asm!(
                "push r24",
                "in r24, 0x3f",
                "push r24",
                concat!("lds r24, ", $reg),
                concat!("andi r24, ", $keep),
                concat!("sts ", $reg, ", r24"),
                "pop r24",
                "out 0x3f, r24",
                "pop r24",
                "sei",
                "jmp {h}",
                h = sym $handler,
            );
        }
    };
}
