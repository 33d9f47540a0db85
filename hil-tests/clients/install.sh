#!/bin/bash
# The real clients the HIL tests drive: the senders, pinned, under
# target/clients/: grbl-streamer (PyPI) in a venv, CNCjs (npm); and the
# browser the studio's tests click through, Debian's chromium and
# chromium-driver (/usr/bin/chromium, /usr/bin/chromedriver). Idempotent,
# says what it installs. `cargo xtask test` starts it at once, in the background, so the
# downloads overlap the host tests; each sender test runs it again first
# (then it finds everything in place).
set -eu
cd "$(dirname "$0")/../.."
clients=target/clients
GRBL_STREAMER=grbl-streamer==2.0.2
CNCJS=1.11.5
mkdir -p "$clients"

venv=$clients/venv
if ! "$venv/bin/python" -c 'import grbl_streamer' 2>/dev/null; then
    echo "install.sh: installing $GRBL_STREAMER into $venv" >&2
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet "$GRBL_STREAMER"
fi

# A marker written after npm succeeded tells a whole install from an
# interrupted one; --prefer-offline: what npm's cache holds is not asked for
# again.
prefix=$clients/cncjs
marker=$prefix/installed-$CNCJS
if [ ! -e "$marker" ]; then
    echo "install.sh: installing cncjs@$CNCJS into $prefix" >&2
    start=$(date +%s)
    npm install --prefix "$prefix" --save-exact --prefer-offline --no-audit \
        --no-fund --loglevel=error "cncjs@$CNCJS"
    grep -q "\"version\": \"$CNCJS\"" "$prefix/node_modules/cncjs/package.json"
    touch "$marker"
    echo "install.sh: cncjs@$CNCJS installed in $(($(date +%s) - start)) s" >&2
fi

# The browser for the studio's tests: Debian's packages, as root (CI and
# these machines run as root; otherwise through sudo if it asks no
# password). apt waits for another install's lock rather than failing.
browser=()
for p in chromium chromium-driver; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || browser+=("$p")
done
if [ ${#browser[@]} -gt 0 ]; then
    echo "install.sh: installing Debian packages: ${browser[*]}" >&2
    start=$(date +%s)
    sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo -n"
    apt="$sudo env DEBIAN_FRONTEND=noninteractive apt-get -o DPkg::Lock::Timeout=600 -q"
    $apt update >/dev/null
    $apt install -y --no-install-recommends "${browser[@]}" >/dev/null
    echo "install.sh: ${browser[*]} installed in $(($(date +%s) - start)) s" >&2
fi
