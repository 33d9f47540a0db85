#!/bin/sh
# The independent SVG reader the SVG tests compare with: Python's
# svgelements (PyPI), pinned, in a venv under target/clients/. Idempotent,
# says what it installs.
set -eu
cd "$(dirname "$0")/../../.."
SVGELEMENTS=svgelements==1.9.6
venv=target/clients/svg-venv
mkdir -p target/clients
# The tests of one run call this at once: the first installs, the rest wait.
exec 9>target/clients/svg-venv.lock
flock 9
if ! "$venv/bin/python" -c 'import svgelements' 2>/dev/null; then
    echo "install.sh: installing $SVGELEMENTS into $venv" >&2
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet "$SVGELEMENTS"
fi
