//! Text kept in flash. On AVR every string literal is otherwise copied into
//! SRAM at start-up; log messages and banners live here instead and are read
//! byte by byte with `lpm`.

use core::arch::asm;

/// A string stored in program memory (below 64 KiB, where `.progmem.data`
/// is placed right after the interrupt vectors).
#[derive(Clone, Copy)]
pub struct FlashStr {
    ptr: *const u8,
    len: u16,
}

impl FlashStr {
    /// # Safety
    /// `ptr` and `len` must be a static placed in `.progmem.data` by
    /// [`flash_str!`]: `byte` reads it from flash with `lpm`.
    #[doc(hidden)]
    pub const unsafe fn from_progmem(ptr: *const u8, len: usize) -> FlashStr {
        FlashStr {
            ptr,
            len: len as u16,
        }
    }

    pub fn len(&self) -> usize {
        self.len as usize
    }

    pub fn byte(&self, i: usize) -> u8 {
        let addr = self.ptr.wrapping_add(i);
        let b: u8;
        // SAFETY: `addr` lies inside a progmem static (constructor contract);
        // `lpm` reads flash and has no other effect.
        unsafe { asm!("lpm {0}, Z", out(reg) b, in("Z") addr, options(pure, readonly, nostack)) };
        b
    }
}

impl ufmt::uDisplay for FlashStr {
    fn fmt<W: ufmt::uWrite + ?Sized>(
        &self,
        f: &mut ufmt::Formatter<'_, W>,
    ) -> Result<(), W::Error> {
        let mut chunk = [0u8; 16];
        let mut i = 0;
        while i < self.len() {
            let mut n = (self.len() - i).min(chunk.len());
            // Never cut inside a UTF-8 sequence (continuation bytes are 10xxxxxx).
            while n > 1 && i + n < self.len() && self.byte(i + n) & 0xC0 == 0x80 {
                n -= 1;
            }
            for (k, c) in chunk[..n].iter_mut().enumerate() {
                *c = self.byte(i + k);
            }
            // SAFETY: the bytes are a whole-character slice of a `&str`
            // literal (see `flash_str!`); `from_utf8` would pull a 256-byte
            // table into SRAM.
            f.write_str(unsafe { core::str::from_utf8_unchecked(&chunk[..n]) })?;
            i += n;
        }
        Ok(())
    }
}

/// The bytes of `s` from `skip` on, as an array, at compile time.
pub const fn bytes<const N: usize>(s: &str, skip: usize) -> [u8; N] {
    let b = s.as_bytes();
    let mut out = [0u8; N];
    let mut i = 0;
    while i < N {
        out[i] = b[skip + i];
        i += 1;
    }
    out
}

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
        let s = unsafe { $crate::board::flash::FlashStr::from_progmem(S.as_ptr(), LEN) };
        s
    }};
}
