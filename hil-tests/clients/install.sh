#!/bin/sh
# The real senders the HIL tests drive, pinned, under target/clients/:
# grbl-streamer (PyPI) in a venv, CNCjs (npm). Idempotent, says what it
# installs. `cargo xtask test` starts it at once, in the background, so the
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
