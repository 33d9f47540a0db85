#!/usr/bin/env bash
# Bootstrap: installs what building and simulating the firmware needs, and
# says what it installs. Idempotent: a second run installs nothing.
#   Debian packages: gcc-avr avr-libc (AVR linker and libc), libelf-dev
#   libclang-dev zlib1g-dev libzstd-dev pkg-config make (simavr-ffi builds
#   simavr and its bindings), avrdude (flashing a Mega, and the flashing
#   tests), arduino-core-avr (the Mega's stock bootloader, which the
#   simulator powers on with), libudev-dev (ravedude's serial ports);
#   ravedude from crates.io (`cargo run` in firmware/ flashes through it);
#   the firmware's pinned nightly (the channel in
#   firmware/rust-toolchain.toml, e.g. nightly-2026-05-20) with rust-src
#   (core is rebuilt for avr-none). The project's machines are not meant to
#   download toolchains, so an installed toolchain that is exactly the pinned
#   commit (the `commit-hash:` line of that file), such as a plain `nightly`
#   of that day, is taken under the pinned name (a link in rustup's toolchain
#   folder); otherwise rustup installs it.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"

APT_PACKAGES=(gcc-avr avr-libc libelf-dev libclang-dev zlib1g-dev libzstd-dev pkg-config make
    avrdude arduino-core-avr libudev-dev)

missing=()
for p in "${APT_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]})); then
    cmd="apt-get update && apt-get install -y --no-install-recommends ${missing[*]}"
    if [ "$(id -u)" -ne 0 ]; then
        if command -v sudo >/dev/null && sudo -n true 2>/dev/null; then
            echo "setup: installing Debian packages: ${missing[*]}"
            sudo sh -c "DEBIAN_FRONTEND=noninteractive $cmd"
        else
            echo "setup: missing Debian packages: ${missing[*]}" >&2
            echo "setup: run as root:  sudo sh -c '$cmd'" >&2
            exit 1
        fi
    else
        echo "setup: installing Debian packages: ${missing[*]}"
        sh -c "DEBIAN_FRONTEND=noninteractive $cmd" >/tmp/taut-apt.log 2>&1 || {
            tail -20 /tmp/taut-apt.log >&2
            exit 1
        }
    fi
fi

if ! command -v rustup >/dev/null; then
    echo "setup: rustup is required (https://rustup.rs)" >&2
    exit 1
fi
# The firmware's pinned nightly.
TOOLCHAIN_FILE="$ROOT/firmware/rust-toolchain.toml"
PIN=$(sed -n 's/^channel *= *"\(.*\)"/\1/p' "$TOOLCHAIN_FILE")
PIN_HASH=$(sed -n 's/^# *commit-hash: *\([0-9a-f]*\).*/\1/p' "$TOOLCHAIN_FILE")
[ -n "$PIN" ] || { echo "setup: no channel in $TOOLCHAIN_FILE" >&2; exit 1; }
export RUSTUP_AUTO_INSTALL=0 # a probe must not start a download
TOOLCHAINS="${RUSTUP_HOME:-$HOME/.rustup}/toolchains"
HOST=$(rustup show 2>/dev/null | sed -n 's/^Default host: *//p')
[ -n "$HOST" ] || { echo "setup: cannot tell rustup's host triple (rustup show)" >&2; exit 1; }
PIN_DIR="$TOOLCHAINS/$PIN-$HOST"

# The commit of an installed toolchain's rustc (its folder), or nothing.
commit_of() { "$1/bin/rustc" -vV 2>/dev/null | sed -n 's/^commit-hash: *//p'; }

if [ -d "$PIN_DIR" ] && [ -n "$PIN_HASH" ] && [ "$(commit_of "$PIN_DIR")" != "$PIN_HASH" ]; then
    if [ -L "$PIN_DIR" ]; then
        # Our link, to a toolchain that has been updated since.
        echo "setup: $PIN linked to $(readlink "$PIN_DIR"), which is rustc $(commit_of "$PIN_DIR"), not $PIN_HASH: link removed"
        rm "$PIN_DIR"
    else
        echo "setup: the installed $PIN is rustc $(commit_of "$PIN_DIR"), not the $PIN_HASH that $TOOLCHAIN_FILE names" >&2
        exit 1
    fi
fi
if [ ! -d "$PIN_DIR" ] && [ -n "$PIN_HASH" ]; then
    for dir in "$TOOLCHAINS"/*; do
        if [ -d "$dir" ] && [ ! -L "$dir" ] && [ "$(commit_of "$dir")" = "$PIN_HASH" ]; then
            echo "setup: $PIN is the installed $(basename "$dir") (rustc $PIN_HASH): linked as $PIN"
            ln -s "$(basename "$dir")" "$PIN_DIR"
            break
        fi
    done
fi
if [ ! -d "$PIN_DIR" ]; then
    echo "setup: installing the firmware's pinned toolchain $PIN"
    if ! rustup toolchain install "$PIN" --profile minimal --component rust-src --component clippy; then
        echo "setup: cannot install $PIN, and no installed toolchain is its commit ${PIN_HASH:-(none named)}." >&2
        echo "setup: installed: $(rustup toolchain list | tr '\n' ' ')" >&2
        echo "setup: install it where a download works, or move the pin to an installed nightly (docs/toolchain.md)." >&2
        exit 1
    fi
    if [ -n "$PIN_HASH" ] && [ "$(commit_of "$PIN_DIR")" != "$PIN_HASH" ]; then
        echo "setup: $PIN installed as rustc $(commit_of "$PIN_DIR"), but $TOOLCHAIN_FILE names $PIN_HASH: fix the commit-hash line" >&2
        exit 1
    fi
fi
if [ ! -d "$("$PIN_DIR/bin/rustc" --print sysroot)/lib/rustlib/src/rust/library/core" ]; then
    echo "setup: installing rust-src for $PIN (core is rebuilt for avr-none)"
    rustup component add rust-src --toolchain "$PIN"
fi
if [ ! -x "$PIN_DIR/bin/cargo-clippy" ]; then
    echo "setup: installing clippy for $PIN (the firmware's lints)"
    rustup component add clippy --toolchain "$PIN"
fi

# ravedude (the firmware's cargo runner), with the host's stable toolchain.
if ! command -v ravedude >/dev/null && [ ! -x "${CARGO_HOME:-$HOME/.cargo}/bin/ravedude" ]; then
    echo "setup: installing ravedude from crates.io (cargo install --locked ravedude)"
    cargo install --locked --quiet ravedude
fi
