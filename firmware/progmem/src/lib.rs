//! Constant text that the AVR keeps in flash. A string literal in Rust is
//! copied into SRAM at start-up on the AVR (a pointer cannot reach flash);
//! [`text!`] places it in `.progmem.data` instead, and [`Text`] reads it
//! back byte by byte with `lpm`. On the host it is ordinary memory, so the
//! logic crate's tests read the same texts. [`table!`] does the same for
//! constant values of any type.
#![no_std]
#![cfg_attr(target_arch = "avr", feature(asm_experimental_arch))]

/// A constant text made by [`text!`].
#[derive(Clone, Copy)]
pub struct Text {
    ptr: *const u8,
    len: u16,
}

// SAFETY: points into a static, immutable, for the whole program.
unsafe impl Sync for Text {}
unsafe impl Send for Text {}

impl Text {
    /// # Safety
    /// `bytes` must be a static made by [`text!`] (in `.progmem.data` on
    /// the AVR), holding a whole `&str`.
    #[doc(hidden)]
    pub const unsafe fn from_static(bytes: &'static [u8]) -> Text {
        Text {
            ptr: bytes.as_ptr(),
            len: bytes.len() as u16,
        }
    }

    pub fn len(&self) -> usize {
        self.len as usize
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Byte `i` (below [`Text::len`]).
    pub fn byte(&self, i: usize) -> u8 {
        debug_assert!(i < self.len());
        let addr = self.ptr.wrapping_add(i);
        #[cfg(target_arch = "avr")]
        {
            let b: u8;
            // SAFETY: `addr` lies inside a progmem static (`from_static`'s
            // contract); `lpm` reads flash and has no other effect.
            unsafe {
                core::arch::asm!("lpm {0}, Z", out(reg) b, in("Z") addr, options(pure, readonly, nostack))
            };
            b
        }
        #[cfg(not(target_arch = "avr"))]
        // SAFETY: `addr` lies inside the static (`from_static`'s contract).
        unsafe {
            *addr
        }
    }

    pub fn bytes(&self) -> impl Iterator<Item = u8> + '_ {
        (0..self.len()).map(|i| self.byte(i))
    }

    /// Whether `other` spells this text, in any case.
    pub fn eq_ignore_ascii_case(&self, other: &[u8]) -> bool {
        other.len() == self.len()
            && self
                .bytes()
                .zip(other)
                .all(|(a, b)| a.eq_ignore_ascii_case(b))
    }

    /// Whether `other` starts with this text, in any case.
    pub fn is_prefix_of(&self, other: &[u8]) -> bool {
        other.len() >= self.len() && self.eq_ignore_ascii_case(&other[..self.len()])
    }
}

/// A table of constant values made by [`table!`], kept in flash on the
/// AVR: it costs its bytes of flash, not the code that would build each
/// value in place; [`Table::get`] copies one out.
#[derive(Clone, Copy)]
pub struct Table<T: 'static> {
    items: &'static [T],
}

impl<T: Copy> Table<T> {
    /// # Safety
    /// `items` must be a static made by [`table!`] (in `.progmem.data` on
    /// the AVR).
    #[doc(hidden)]
    pub const unsafe fn from_static(items: &'static [T]) -> Table<T> {
        Table { items }
    }

    /// Item `i` copied into `out`, in place: no copy on the stack (a
    /// big item's is, on the AVR, under whatever the caller calls next).
    pub fn get_into(&self, i: usize, out: &mut T) {
        // SAFETY: a whole value of `T` is written, and nothing reads `out`
        // before (the bounds are checked first: no panic midway).
        self.init(i, unsafe {
            &mut *(out as *mut T).cast::<core::mem::MaybeUninit<T>>()
        });
    }

    /// Item `i` written into `out`, in place (as [`Table::get_into`]).
    pub fn init<'a>(&self, i: usize, out: &'a mut core::mem::MaybeUninit<T>) -> &'a mut T {
        let item = &self.items[i];
        #[cfg(target_arch = "avr")]
        {
            let from = (item as *const T).cast::<u8>();
            let to = out.as_mut_ptr().cast::<u8>();
            for k in 0..core::mem::size_of::<T>() {
                let b: u8;
                // SAFETY: `from + k` lies inside the progmem static
                // (`from_static`'s contract); `lpm` reads flash and has no
                // other effect; `to + k` inside `out`.
                unsafe {
                    core::arch::asm!("lpm {0}, Z", out(reg) b, in("Z") from.wrapping_add(k), options(pure, readonly, nostack));
                    to.add(k).write(b);
                }
            }
        }
        #[cfg(not(target_arch = "avr"))]
        out.write(*item);
        // SAFETY: every byte of `out` written from a value of `T`, `Copy`.
        unsafe { out.assume_init_mut() }
    }

    /// A copy of item `i`, read a byte at a time with `lpm` on the AVR.
    pub fn get(&self, i: usize) -> T {
        let mut out = core::mem::MaybeUninit::uninit();
        *self.init(i, &mut out)
    }
}

impl PartialEq for Text {
    fn eq(&self, other: &Text) -> bool {
        self.len == other.len && self.bytes().eq(other.bytes())
    }
}

impl Eq for Text {}

impl core::fmt::Debug for Text {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        core::fmt::Display::fmt(self, f)
    }
}

impl core::fmt::Display for Text {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        self.bytes()
            .try_for_each(|b| core::fmt::Write::write_char(f, b as char))
    }
}

impl ufmt::uDisplay for Text {
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
            // SAFETY: whole characters of a `&str` literal (see `text!`);
            // `from_utf8` would pull a 256-byte table into SRAM.
            f.write_str(unsafe { core::str::from_utf8_unchecked(&chunk[..n]) })?;
            i += n;
        }
        Ok(())
    }
}

/// The bytes of `s` from `skip` on, as an array, at compile time.
#[doc(hidden)]
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

/// A string literal as a [`Text`] kept in flash on the AVR.
#[macro_export]
macro_rules! text {
    ($s:expr) => {{
        const S: &str = $s;
        #[cfg_attr(target_arch = "avr", link_section = ".progmem.data")]
        static T: [u8; S.len()] = $crate::bytes(S, 0);
        // SAFETY: `T` is a static holding the whole of `S`, in flash on
        // the AVR.
        unsafe { $crate::Text::from_static(&T) }
    }};
}

/// An array of constant values as a [`Table`] kept in flash on the AVR:
/// `table!(T; N; [a, b, …])`.
#[macro_export]
macro_rules! table {
    ($t:ty; $n:expr; $items:expr) => {{
        #[cfg_attr(target_arch = "avr", link_section = ".progmem.data")]
        static T: [$t; $n] = $items;
        // SAFETY: `T` is a static, in flash on the AVR.
        unsafe { $crate::Table::from_static(&T) }
    }};
}

/// The names of a fieldless enum's variants as a [`Table`] of [`Text`]s
/// in flash, indexed by discriminant: `text_table!(Enum; [A => "a", B =>
/// "b"]).get(v as usize)`. Every variant, in discriminant order from 0
/// (both checked at compile time). On the AVR a `match` returning a text
/// per variant costs ~15 bytes of code per arm; an entry here costs 4.
#[macro_export]
macro_rules! text_table {
    ($ty:ident; [$($v:ident => $s:expr),* $(,)?]) => {{
        const N: usize = [$(stringify!($v)),*].len();
        const _: () = {
            let mut i = 0;
            $(
                assert!($ty::$v as usize == i);
                i += 1;
            )*
            assert!(i == N);
        };
        // Not called: fails to compile if a variant is missing.
        #[allow(dead_code)]
        const fn every_variant(v: $ty) {
            match v {
                $($ty::$v => {})*
            }
        }
        $crate::table!($crate::Text; N; [$($crate::text!($s)),*])
    }};
}

#[cfg(test)]
mod tests {
    extern crate std;
    use std::string::ToString;

    #[test]
    fn texts_read_compare_and_print() {
        let t = text!("base_max_rate");
        assert_eq!(t.len(), 13);
        assert!(t.eq_ignore_ascii_case(b"BASE_Max_Rate"));
        assert!(!t.eq_ignore_ascii_case(b"base_max_rat"));
        assert!(text!("base").is_prefix_of(b"base_accel"));
        assert_eq!(t.to_string(), "base_max_rate");
        assert_eq!(text!("čas"), text!("čas"));
    }
}
