#!/usr/bin/env bash
# Create bench/.venv-peers with the peer libraries the benchmarks compare poppy against:
# pypot (+ poppy-ergo-jr for the REST benchmark, poppy-torso for the teleoperation benchmark's
# arms_copy_motion) and the Robotis dynamixel-sdk.
# Idempotent and quiet: prints one summary line; pip output goes to .venv-peers/install.log
# and is shown only when a step fails. Usage: bash bench/setup_peers.sh [--force]
#
# pypot declares heavy dependencies it never imports for the bus or REST paths
# (opencv-contrib-python, matplotlib via hampy, requests, wget). So pypot, poppy-ergo-jr,
# poppy-torso and ikpy are installed with --no-deps and only what their imports need is added
# (see bench/README.md, "Peers venv").
set -euo pipefail

HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
VENV="$HERE/.venv-peers"
PYTHON="${PYTHON:-python3.11}"
LOG="$VENV/install.log"

# Exact peer versions, so results stay comparable between runs.
PEERS_NODEPS=(pypot==5.0.2 poppy-ergo-jr==4.0.2 poppy-torso==3.0.0 ikpy==3.0.1)
CORE_DEPS=(dynamixel-sdk==4.1.0 "pyserial>=3.5" "numpy>=1.26")
# Imported by pypot.creatures / pypot.server / poppy_ergo_jr (REST benchmark; pyzmq: ZMQ benchmark).
REST_DEPS=(scipy sympy tornado bottle opencv-python-headless pyzmq)

STAMP_TEXT="$PYTHON ${PEERS_NODEPS[*]} ${CORE_DEPS[*]} ${REST_DEPS[*]}"
STAMP="$VENV/.installed"

if [[ "${1:-}" != "--force" && -f "$STAMP" && "$(cat "$STAMP")" == "$STAMP_TEXT" ]]; then
    exit 0
fi

fail() {
    echo "setup_peers: $1 failed; log follows ($LOG)" >&2
    tail -n 40 "$LOG" >&2
    exit 1
}

if [[ ! -x "$VENV/bin/python" ]]; then
    command -v "$PYTHON" >/dev/null || { echo "setup_peers: $PYTHON not found" >&2; exit 1; }
    "$PYTHON" -m venv "$VENV"
fi
: >"$LOG"
PIP=("$VENV/bin/python" -m pip --disable-pip-version-check)

"${PIP[@]}" install --upgrade pip >>"$LOG" 2>&1 || fail "pip upgrade"
"${PIP[@]}" install --no-deps "${PEERS_NODEPS[@]}" >>"$LOG" 2>&1 || fail "peer install"
"${PIP[@]}" install "${CORE_DEPS[@]}" >>"$LOG" 2>&1 || fail "core deps"

rest="yes"
if ! "${PIP[@]}" install "${REST_DEPS[@]}" >>"$LOG" 2>&1; then
    rest="no"
    echo "setup_peers: REST deps failed to install; poppy-ergo-jr unusable (see $LOG)" >&2
fi

"$VENV/bin/python" - >>"$LOG" 2>&1 <<'PY' || fail "import check (scan)"
import dynamixel_sdk, pypot.dynamixel, pypot.robot
PY
if [[ "$rest" == "yes" ]]; then
    "$VENV/bin/python" - >>"$LOG" 2>&1 <<'PY' || { rest="no"; echo "setup_peers: poppy_ergo_jr import failed (see $LOG)" >&2; }
# pypot.creatures must be imported first: importing poppy_ergo_jr first leaves the
# creature registry empty (circular import inside pypot.creatures).
import pypot.creatures, pypot.server.httpserver
assert "poppy-ergo-jr" in pypot.creatures.installed_poppy_creatures
from poppy_torso.primitives.interaction import PuppetMaster  # teleop benchmark
PY
fi

if [[ "$rest" == "yes" ]]; then
    echo "$STAMP_TEXT" >"$STAMP"
fi
# wrk (Debian) loads the REST benchmark; without it a Python client caps what can be measured.
if ! command -v wrk >/dev/null 2>&1 && command -v apt-get >/dev/null 2>&1; then
    if [[ "$(id -u)" == 0 ]]; then
        { apt-get update -qq && apt-get install -y -qq wrk; } >>"$LOG" 2>&1 \
            || echo "setup_peers: could not install wrk (see $LOG)" >&2
    else
        echo "setup_peers: install wrk for the REST benchmark: sudo apt-get install wrk" >&2
    fi
fi

versions="$("$VENV/bin/python" -c 'from importlib.metadata import version as v
print(" ".join(f"{p}={v(p)}" for p in ("pypot", "dynamixel-sdk", "poppy-ergo-jr", "poppy-torso")))')"
echo "setup_peers: $VENV ready ($versions, rest=$rest)"
