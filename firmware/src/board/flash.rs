//! Text kept in flash. On AVR every string literal is otherwise copied into
//! SRAM at start-up; log messages and banners live here instead and are read
//! byte by byte with `lpm`.

/// A string stored in program memory (below 64 KiB, where `.progmem.data`
/// is placed right after the interrupt vectors): the logic crate's texts
/// and the firmware's are one type.
pub use taut_progmem::Text as FlashStr;

/// The bytes of `s` from `skip` on, as an array, at compile time.
pub use taut_progmem::bytes;

/// Where a module path continues after its crate name (`taut_firmware::`).
pub const fn after_crate_name(path: &str) -> usize {
    let b = path.as_bytes();
    let mut i = 0;
    while i + 1 < b.len() {
        if b[i] == b':' && b[i + 1] == b':' {
            return i + 2;
        }
        i += 1;
    }
    0
}

/// Place a string literal (or `concat!`/`env!` of them) in flash.
#[macro_export]
macro_rules! flash_str {
    ($s:expr) => {{
        const LEN: usize = $s.len();
        // Allowed here: the modules using the macro deny unsafe code.
        #[allow(unsafe_code)]
        #[link_section = ".progmem.data"]
        static S: [u8; LEN] = $crate::board::flash::bytes::<LEN>($s, 0);
        #[allow(unsafe_code)]
        // SAFETY: S is a progmem static of LEN bytes.
        let s = unsafe { $crate::board::flash::FlashStr::from_static(&S) };
        s
    }};
}

/// The module path without the crate name, at compile time, in flash.
#[macro_export]
#[doc(hidden)]
macro_rules! __log_module {
    () => {{
        const FULL: &str = module_path!();
        const SKIP: usize = $crate::board::flash::after_crate_name(FULL);
        const LEN: usize = FULL.len() - SKIP;
        // Allowed here: the modules using the macro deny unsafe code.
        #[allow(unsafe_code)]
        #[link_section = ".progmem.data"]
        static S: [u8; LEN] = $crate::board::flash::bytes::<LEN>(FULL, SKIP);
        #[allow(unsafe_code)]
        // SAFETY: S is a progmem static of LEN bytes.
        let s = unsafe { $crate::board::flash::FlashStr::from_static(&S) };
        s
    }};
}
