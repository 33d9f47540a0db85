#!/usr/bin/env bash
# The firmware's linker (`.cargo/config.toml`): avr-gcc as rustc calls it,
# twice, so that byte 0x20000 holds the watchdog entry (src/board/early.rs).
#
# The Mega's stock STK500v2 bootloader, after a watchdog reset, calls the
# application through `eicall` with EIND = 1: word 0x10000, byte 0x20000,
# not 0. An image over 128 KiB has code of its own there. So:
#   1. link as usual, with a map;
#   2. read from the map the function sections of `.text` in order and
#      keep below 0x20000 each that still fits there (first fit, a few
#      trampolines' room kept spare), skipping those that do not;
#   3. link again with the default script changed so that those sections
#      stay where they were, `.text` goes on at 0x20000 with the watchdog
#      entry, then every other function.
# The image stays one run of bytes from 0: the gap before 0x20000 (less
# than the smallest function left above it, and the spare room; all of
# the rest up to it in a small image) is filled
# (zeros: `nop`s). That bootloader erases pages in the order it writes
# them, counting from 0 whatever address it is told: a hole in the hex
# would make it erase each page after the hole just after writing it.
# The build's end mark (`.endmark`) goes last, after `.data`'s values: the
# start-up checks it is there (a write cut short leaves it out).
set -euo pipefail

out=
prev=
for a in "$@"; do
    [ "$prev" = "-o" ] && out=$a
    prev=$a
done
[ -n "$out" ] || exec avr-gcc "$@"

map="$out.pass1.map"
script="$out.ld"
avr-gcc "$@" -Wl,-Map="$map"

# The default script of the ATmega2560's architecture, from the linker.
default=$(avr-ld --verbose -mavr6 | awk '/^====/ { inside = !inside; next } inside')
[ -n "$default" ] || { echo "avr-link.sh: cannot read the linker's default script" >&2; exit 1; }

# The `.text.*` input sections kept below 0x20000: in the order the first
# link placed them, from where it placed the first, each that still fits
# (sizes rounded to a word); the others go above. 64 bytes stay spare:
# a function moved above may need a trampoline (4 bytes) below (names
# may stand on a line of their own, before their address and size).
low=$(awk '
    function hex(s,   i, v) {
        s = tolower(s); sub(/^0x/, "", s); v = 0
        for (i = 1; i <= length(s); i++) v = v * 16 + index("0123456789abcdef", substr(s, i, 1)) - 1
        return v
    }
    function place(name, addr, size,   end) {
        if (n == 0 && !crossed) at = hex(addr)
        end = at + hex(size) + hex(size) % 2
        if (end > 131072 - 64) { crossed = 1; return }
        at = end
        low[n++] = "    *(" name ")"
    }
    /^\.text[ \t]/ || $0 == ".text" { in_text = 1; next }
    /^\.[a-z]/ { in_text = 0 }
    !in_text { next }
    pending != "" && $1 ~ /^0x/ { place(pending, $1, $2); pending = ""; next }
    $1 ~ /^\.text\./ {
        if (NF >= 3 && $2 ~ /^0x/) place($1, $2, $3); else pending = $1
    }
    END {
        if (!crossed) { print "ALL"; exit }
        for (i = 0; i < n; i++) print low[i]
    }
' "$map")

if [ "$low" = "ALL" ]; then
    low='    *(.text.*)'
fi
text_rule="$low
    . = 0x20000;
    KEEP (*(.watchdog_entry))
    *(.text.*)"

# The default script, its `*(.text.*)` in `.text` replaced by the low
# sections, the entry at 0x20000 and the rest; the end mark after `.data`;
# `.noinit` not loaded.
printf '%s\n' "$default" | awk -v rule="$text_rule" '
    /^[ \t]*\.text[ \t]*:/ { in_text = 1 }
    # Statics of Rust in `.noinit` are PROGBITS (zeros): not for flash.
    /^[ \t]*\.noinit[ \t]/ { print "  .noinit (NOLOAD) :"; next }
    in_text && /^[ \t]*\*\(\.text\.\*\)/ { print rule; next }
    { print }
    /^[ \t]*}[ \t]*>[ \t]*data[ \t]+AT>[ \t]*text/ {
        print "  .endmark :"
        print "  {"
        print "    KEEP (*(.endmark))"
        print "  }  > text"
    }
    in_text && /^[ \t]*}[ \t]*>[ \t]*text/ { in_text = 0 }
' > "$script"

# --emit-relocs: the relocations stay in the ELF (not in flash), for
# `cargo xtask build`'s check of every function pointer.
avr-gcc "$@" -Wl,-T,"$script" -Wl,-Map="$out.map" -Wl,--emit-relocs
rm -f "$map"
