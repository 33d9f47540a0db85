#!/bin/sh
# The independent SVG reader the SVG tests compare with: Python's
# svgelements (PyPI), pinned, in a venv under target/clients/. Idempotent,
# says what it installs.
set -eu
cd "$(dirname "$0")/../../.."
SVGELEMENTS=svgelements==1.9.6
venv=target/clients/svg-venv
if ! "$venv/bin/python" -c 'import svgelements' 2>/dev/null; then
    echo "install.sh: installing $SVGELEMENTS into $venv" >&2
    mkdir -p target/clients
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet "$SVGELEMENTS"
fi
