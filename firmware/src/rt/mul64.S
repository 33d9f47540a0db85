; The image's 64-bit product, `__muldi3`, in place of libgcc's; why and
; how it is checked: mul64.rs beside this file. Assembled and linked as an
; object of every image by build.rs.
;
; Calling convention (avr-gcc's, which LLVM follows for the call): a in
; r18-r25 and b in r10-r17, low byte first, the product in r18-r25;
; r2-r17 and r28-r29 kept, r1 zero again at the end.

    .section .text.__muldi3,"ax",@progbits
    .global __muldi3
    .type __muldi3, @function
__muldi3:
    push r2
    push r3
    push r4
    push r5
    push r6
    push r7
    push r8
    push r9
    push r28
    clr r28                 ; the zero taut_mul32 carries with
    movw r2, r18            ; X = a_lo
    movw r4, r20
    ; Both high halves zero: one product of the low halves.
    mov r0, r22
    or r0, r23
    or r0, r24
    or r0, r25
    or r0, r14
    or r0, r15
    or r0, r16
    or r0, r17
    brne 1f
    movw r6, r10            ; Y = b_lo
    movw r8, r12
    rcall taut_mul32
    rjmp 2f
1:  ; a_hi * b_lo, its low half kept in r18-r21 (a_lo moves to X first).
    movw r2, r22
    movw r4, r24
    movw r6, r10
    movw r8, r12
    rcall taut_mul32
    movw r2, r18
    movw r4, r20
    movw r18, r22
    movw r20, r24
    ; Plus the low half of a_lo * b_hi.
    movw r6, r14
    movw r8, r16
    rcall taut_mul32
    add r18, r22
    adc r19, r23
    adc r20, r24
    adc r21, r25
    ; a_lo * b_lo, the cross sum added to its high half.
    movw r6, r10
    movw r8, r12
    rcall taut_mul32
    add r26, r18
    adc r27, r19
    adc r30, r20
    adc r31, r21
2:  movw r18, r22
    movw r20, r24
    movw r22, r26
    movw r24, r30
    pop r28
    pop r9
    pop r8
    pop r7
    pop r6
    pop r5
    pop r4
    pop r3
    pop r2
    ret
    .size __muldi3, . - __muldi3

; X (r2-r5) * Y (r6-r9) -> r22-r27, r30, r31 (low byte first), with r28
; zero. Column c's products (bytes i + j = c) are added into result bytes
; c, c+1 and c+2 (c+2 cleared first): a column's sum with what came
; before stays below 2^(8(c+3)). Clobbers r0, r1 (cleared at the end).
    .type taut_mul32, @function
taut_mul32:
    mul r2, r6              ; column 0
    movw r22, r0
    clr r24
    clr r25
    mul r2, r7              ; column 1
    add r23, r0
    adc r24, r1
    adc r25, r28
    mul r3, r6
    add r23, r0
    adc r24, r1
    adc r25, r28
    clr r26                 ; column 2
    mul r2, r8
    add r24, r0
    adc r25, r1
    adc r26, r28
    mul r3, r7
    add r24, r0
    adc r25, r1
    adc r26, r28
    mul r4, r6
    add r24, r0
    adc r25, r1
    adc r26, r28
    clr r27                 ; column 3
    mul r2, r9
    add r25, r0
    adc r26, r1
    adc r27, r28
    mul r3, r8
    add r25, r0
    adc r26, r1
    adc r27, r28
    mul r4, r7
    add r25, r0
    adc r26, r1
    adc r27, r28
    mul r5, r6
    add r25, r0
    adc r26, r1
    adc r27, r28
    clr r30                 ; column 4
    mul r3, r9
    add r26, r0
    adc r27, r1
    adc r30, r28
    mul r4, r8
    add r26, r0
    adc r27, r1
    adc r30, r28
    mul r5, r7
    add r26, r0
    adc r27, r1
    adc r30, r28
    clr r31                 ; column 5
    mul r4, r9
    add r27, r0
    adc r30, r1
    adc r31, r28
    mul r5, r8
    add r27, r0
    adc r30, r1
    adc r31, r28
    mul r5, r9              ; column 6: below 2^64, nothing carries out
    add r30, r0
    adc r31, r1
    clr r1
    ret
    .size taut_mul32, . - taut_mul32
