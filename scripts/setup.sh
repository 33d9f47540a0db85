#!/usr/bin/env bash
# Bootstrap: installs what building and simulating the firmware needs, and
# says what it installs. Idempotent: a second run installs nothing.
#   Debian packages: gcc-avr avr-libc (AVR linker and libc), libelf-dev
#   libclang-dev zlib1g-dev libzstd-dev pkg-config make (simavr-ffi builds
#   simavr and its bindings); rustup's nightly toolchain with rust-src
#   (core is rebuilt for avr-none).
set -euo pipefail

APT_PACKAGES=(gcc-avr avr-libc libelf-dev libclang-dev zlib1g-dev libzstd-dev pkg-config make)

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
if ! rustup toolchain list | grep -q '^nightly'; then
    echo "setup: installing the nightly toolchain"
    rustup toolchain install nightly --profile minimal
fi
if ! rustup component list --toolchain nightly --installed | grep -q '^rust-src'; then
    echo "setup: installing rust-src for nightly (core is rebuilt for avr-none)"
    rustup component add rust-src --toolchain nightly
fi
