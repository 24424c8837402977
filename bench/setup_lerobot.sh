#!/usr/bin/env bash
# Create bench/.venv-lerobot: LeRobot 0.4.4, the oracle of the dataset tests (tests/dataset/):
# its own LeRobotDataset loads and decodes what poppy_core.dataset writes, and writes the
# info.json poppy's is compared with; and the home of the LeRobot plugin's tests
# (tests/lerobot_plugin/): lerobot-teleoperate, -record, -replay and -train on a Poppy robot.
# Poppy itself never imports torch or lerobot.
# Idempotent and quiet: one summary line; pip output goes to .venv-lerobot/install.log and is
# shown only when a step fails. Usage: bash bench/setup_lerobot.sh [--force]
#
# lerobot 0.4.4 pins torch<2.11, torchvision<0.26 and torchcodec<0.11, and asks for training
# and hardware libraries (diffusers, wandb, rerun-sdk, pynput, opencv...) that loading a
# dataset never imports. Here lerobot is installed with --no-deps, beside:
# - torch 2.14.1 + torchvision 0.29.1: pip takes both from this machine's disk (a CUDA build,
#   run on the CPU). The CPU-only torch 2.13.0 on disk cannot be used: no torchvision imports
#   beside it ("operator torchvision::nms does not exist"), and lerobot imports torchvision.
#   triton (torch.compile only) is removed afterwards (0.9 GB).
# - torchcodec, lerobot's default video decoder: torchvision >= 0.24 has no VideoReader, so
#   lerobot's "pyav" backend cannot decode there. torchcodec loads the system's FFmpeg
#   (Debian's ffmpeg package, installed here when run as root).
# - what lerobot.datasets imports: datasets, huggingface-hub, pandas, pyarrow, av, accelerate...
# - what LeRobot's command lines import (opencv, rerun-sdk, pyserial, imageio, gymnasium), and
#   poppy's runtime dependencies (its core, the sim extra, eclipse-zenoh for zenoh:NAME),
#   read from this clone's pyproject.toml. Poppy and the plugin themselves are not installed
#   here: the venv is shared by every clone of the repository, so each test run installs the
#   plugin into a folder of its own and puts its clone first on PYTHONPATH
#   (tests/lerobot_plugin/conftest.py). Everything is installed with the venv's packages as
#   constraints, so adding packages never changes torch, numpy or lerobot.
# Costs (measured on the 2-core machine, files on disk, PyPI for the small ones): about 3 min
# and 5 GB; see docs/learning.md.
set -euo pipefail

HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
# CI points POPPY_LEROBOT_VENV at a folder outside its fresh clone, kept between its runs on
# one machine (.ci/run); the tests look there, then here.
VENV="${POPPY_LEROBOT_VENV:-$HERE/.venv-lerobot}"
PYTHON="${PYTHON:-python3.11}"
LOG="$VENV/install.log"

LEROBOT=lerobot==0.4.4
TORCH=(torch==2.14.1 torchvision==0.29.1)
DECODER=(torchcodec==0.17.0)
# lerobot.datasets' imports, within lerobot 0.4.4's own bounds where it sets them
DATASET_DEPS=("datasets>=4.0.0,<5.0.0" "huggingface-hub>=0.34.2,<0.36.0" "av>=15.0.0,<16.0.0"
    pandas pyarrow pillow "packaging>=24.2,<26.0" draccus==0.10.0 "jsonlines>=4.0.0,<5.0.0"
    "termcolor>=2.4.0,<4.0.0" "deepdiff>=7.0.1,<9.0.0" "einops>=0.8.0,<0.9.0"
    "accelerate>=1.10.0,<2.0.0")

# lerobot-record, -teleoperate, -replay and -train's imports (lerobot 0.4.4's bounds); pynput
# (keys, needs a display) and wandb are left out: lerobot runs headless and offline without them;
# diffusers is imported by lerobot.policies (groot) whatever the policy
CLI_DEPS=("opencv-python-headless>=4.9.0,<4.13.0" "rerun-sdk>=0.24.0,<0.27.0"
    "pyserial>=3.5,<4.0" "imageio[ffmpeg]>=2.34.0,<3.0.0" "gymnasium>=1.1.1,<2.0.0"
    "diffusers>=0.27.2,<0.36.0"
    # builds the plugin without isolation (tests/lerobot_plugin/conftest.py): no wheel package
    # needed from 70.1 on; `pip freeze` leaves setuptools out of the constraints
    "setuptools>=71")
# poppy's runtime dependencies for the plugin: core + sim extra + Zenoh (zenoh:NAME robots)
mapfile -t POPPY_DEPS < <("$PYTHON" - "$HERE/../pyproject.toml" <<'PY'
import sys
import tomllib

with open(sys.argv[1], "rb") as file:
    project = tomllib.load(file)["project"]
fleet = [d for d in project["optional-dependencies"]["fleet"] if not d.startswith("poppy")]
for dep in project["dependencies"] + project["optional-dependencies"]["sim"] + fleet:
    print(dep)
PY
)

STAMP_TEXT="$PYTHON $LEROBOT ${TORCH[*]} ${DECODER[*]} ${DATASET_DEPS[*]} ${CLI_DEPS[*]} ${POPPY_DEPS[*]}"
STAMP="$VENV/.installed"

if [[ "${1:-}" != "--force" && -f "$STAMP" && "$(cat "$STAMP")" == "$STAMP_TEXT" ]]; then
    exit 0
fi

fail() {
    echo "setup_lerobot: $1 failed; log follows ($LOG)" >&2
    tail -n 40 "$LOG" >&2
    exit 1
}

# torchcodec decodes through the system's FFmpeg libraries
if ! command -v ffmpeg >/dev/null 2>&1; then
    if [[ "$(id -u)" == 0 ]] && command -v apt-get >/dev/null 2>&1; then
        { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
            --no-install-recommends ffmpeg; } >/dev/null 2>&1 \
            || echo "setup_lerobot: could not install Debian's ffmpeg: decoding will fail" >&2
    else
        echo "setup_lerobot: install FFmpeg for torchcodec: sudo apt-get install ffmpeg" >&2
    fi
fi

if [[ ! -x "$VENV/bin/python" ]]; then
    command -v "$PYTHON" >/dev/null || { echo "setup_lerobot: $PYTHON not found" >&2; exit 1; }
    "$PYTHON" -m venv "$VENV"
fi
: >"$LOG"
PIP=("$VENV/bin/python" -m pip --disable-pip-version-check)

"${PIP[@]}" install "${TORCH[@]}" >>"$LOG" 2>&1 || fail "torch install"
"${PIP[@]}" install --no-deps "$LEROBOT" "${DECODER[@]}" >>"$LOG" 2>&1 || fail "lerobot install"
"${PIP[@]}" install "${DATASET_DEPS[@]}" >>"$LOG" 2>&1 || fail "dataset deps"
# what is there stays as it is (a venv made by an older version of this script, used by others)
FROZEN="$VENV/.constraints.txt"
"${PIP[@]}" freeze --exclude-editable >"$FROZEN" 2>>"$LOG" || fail "pip freeze"
"${PIP[@]}" install -c "$FROZEN" "${CLI_DEPS[@]}" "${POPPY_DEPS[@]}" >>"$LOG" 2>&1 \
    || fail "command-line and poppy deps"
# last: installing the deps above brings torch's missing requirements back
"${PIP[@]}" uninstall -y triton >>"$LOG" 2>&1 || fail "triton removal"

"$VENV/bin/python" - >>"$LOG" 2>&1 <<'PY' || fail "import check"
import torchcodec.decoders  # loads FFmpeg: fails here, not in the tests, when it is missing
from lerobot.datasets.lerobot_dataset import LeRobotDataset
import lerobot.scripts.lerobot_record, lerobot.scripts.lerobot_train  # the command lines
import mujoco, zenoh  # poppy's simulation and zenoh:NAME robots
PY

echo "$STAMP_TEXT" >"$STAMP"
versions="$("$VENV/bin/python" -c 'from importlib.metadata import version as v
print(" ".join(f"{p}={v(p)}" for p in ("lerobot", "torch", "torchvision", "torchcodec", "datasets", "mujoco")))')"
echo "setup_lerobot: $VENV ready ($versions, $(du -sh "$VENV" | cut -f1))"
