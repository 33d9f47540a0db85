; The image's `memcpy` and `memset`, in place of avr-libc's: the same
; loops four bytes a turn. Struct moves are what LLVM calls them for (a
; position is 12 bytes, a parsed word list 57): ~1 500 bytes copied a
; line of a stream of short moves, where avr-libc's byte-a-turn loop
; spends 8 cycles a byte (a copy) and 6 (a clear). Here 5 and 3, and 7
; and 5 for the one to three bytes left over. Checked by
; examples/arith_check.rs (HIL test harness::the_images_wide_arithmetic_is_exact).
;
; Calling convention (avr-gcc's, which LLVM follows for these libcalls):
; the destination in r25:r24 (and returned there), the source or the
; value in r23:r22 (r22), the length in r21:r20; r0, r18-r27, r30-r31 may
; be clobbered, r1 is zero and stays so.

    .section .text.memcpy,"ax",@progbits
    .global memcpy
    .type memcpy, @function
memcpy:
    movw r30, r22           ; Z = source
    movw r26, r24           ; X = destination
    mov r18, r20            ; the length modulo 4, after the turns
    lsr r21
    ror r20
    lsr r21
    ror r20                 ; turns: the length / 4
    rjmp 2f
1:  ld r0, Z+
    st X+, r0
    ld r0, Z+
    st X+, r0
    ld r0, Z+
    st X+, r0
    ld r0, Z+
    st X+, r0
2:  subi r20, 1
    sbci r21, 0
    brcc 1b
    andi r18, 3
    breq 4f
3:  ld r0, Z+
    st X+, r0
    dec r18
    brne 3b
4:  ret
    .size memcpy, . - memcpy

    .section .text.memset,"ax",@progbits
    .global memset
    .type memset, @function
memset:
    movw r26, r24           ; X = destination
    mov r18, r20
    lsr r21
    ror r20
    lsr r21
    ror r20
    rjmp 2f
1:  st X+, r22
    st X+, r22
    st X+, r22
    st X+, r22
2:  subi r20, 1
    sbci r21, 0
    brcc 1b
    andi r18, 3
    breq 4f
3:  st X+, r22
    dec r18
    brne 3b
4:  ret
    .size memset, . - memset
