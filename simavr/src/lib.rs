pub fn x() { let _ = unsafe { simavr_ffi::avr_make_mcu_by_name(c"atmega2560".as_ptr()) }; }
