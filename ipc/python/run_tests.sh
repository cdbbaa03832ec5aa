#!/usr/bin/env bash
# The Python client's test suite against the real daemon, for CI.
#
#   ipc/python/run_tests.sh [pytest args...]
#
# Expects the debug `proximad` and the `frame_dump` example that `cargo test --workspace`
# builds under ${CARGO_TARGET_DIR:-target}/debug (builds them if missing). Creates a venv
# under the target directory, installs the package (with iceoryx2==0.10.0 and numpy from
# PyPI) and pytest, and runs the suite with PROXIMA_REQUIRE_DAEMON=1, so a missing daemon
# fails instead of skipping. Set PROXIMA_PYTHON to choose the interpreter (default python3).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
target="${CARGO_TARGET_DIR:-$repo/target}"
case "$target" in /*) ;; *) target="$repo/$target" ;; esac
venv="$target/python-venv"

export PROXIMAD="${PROXIMAD:-$target/debug/proximad}"
export FRAME_DUMP="${FRAME_DUMP:-$target/debug/examples/frame_dump}"
export PROXIMA_REQUIRE_DAEMON=1
export CARGO_TARGET_DIR="$target"

if [[ ! -x "$PROXIMAD" ]]; then
    (cd "$repo" && cargo build --bin proximad)
fi
if [[ ! -x "$FRAME_DUMP" ]]; then
    (cd "$repo" && cargo build -p proxima-ipc --example frame_dump)
fi

if [[ ! -x "$venv/bin/python" ]]; then
    "${PROXIMA_PYTHON:-python3}" -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check "$here" pytest

cd "$here"
exec "$venv/bin/python" -m pytest -q -rs -p no:cacheprovider "$@" tests
