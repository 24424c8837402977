"""The venv MediaPipe Pose runs in: where it is, and ``python -m poppy_core.sensors.pose_venv``
to make it.

MediaPipe 0.10.21 (the last wheel with a pose model inside) pins numpy < 2 and protobuf < 5,
which poppy's own venv cannot hold (numpy 2, Foxglove's protobuf); newer MediaPipe wheels ship
no model and want a downloaded ``.task`` file. So the pose estimator runs as a child process
(``pose_worker.py``) in a venv of its own: ``$POPPY_POSE_VENV``, else
``~/.cache/poppy/venv-pose``. Making it takes PyPI's wheels (about 250 MB, a minute or two);
it is idempotent (a stamp file says what it holds). MediaPipe is installed without its
dependencies and beside only what ``solutions.pose`` imports (jax, jaxlib and sentencepiece,
which it never imports, are left out).
"""

from __future__ import annotations

import os
import subprocess
import sys
import venv
from pathlib import Path

MEDIAPIPE = "mediapipe==0.10.21"
DEPENDENCIES = (
    "numpy>=1.26,<2",
    "protobuf>=4.25.3,<5",
    "opencv-python-headless>=4.8,<4.12",
    "absl-py",
    "attrs>=19.1.0",
    "flatbuffers>=2.0",
    "matplotlib<3.10",
    "sounddevice>=0.4.4",
)
"""What ``mediapipe.python.solutions.pose`` imports, within MediaPipe 0.10.21's bounds; OpenCV
headless in place of its opencv-contrib-python (the same ``cv2`` for what pose needs)."""
STAMP = ".poppy-pose"


def venv_dir() -> Path:
    """The pose venv's folder: ``$POPPY_POSE_VENV`` or ``~/.cache/poppy/venv-pose``."""
    given = os.environ.get("POPPY_POSE_VENV")
    return Path(given) if given else Path.home() / ".cache" / "poppy" / "venv-pose"


def venv_python(folder: Path | None = None) -> Path:
    """The interpreter of the pose venv (it may not exist)."""
    return (folder or venv_dir()) / "bin" / "python"


def stamp_text() -> str:
    """What a made venv holds (its stamp)."""
    return " ".join((f"python{sys.version_info.major}.{sys.version_info.minor}", MEDIAPIPE))


def is_made(folder: Path | None = None) -> bool:
    """Whether the venv at ``folder`` was made with this module's packages."""
    where = folder or venv_dir()
    stamp = where / STAMP
    return venv_python(where).is_file() and stamp.is_file() and stamp.read_text() == stamp_text()


def make(folder: Path | None = None, *, force: bool = False) -> Path:
    """Make (or keep) the pose venv; returns its interpreter.

    Raises:
        subprocess.CalledProcessError: pip failed (its output was shown).
    """
    where = folder or venv_dir()
    python = venv_python(where)
    if not force and is_made(where):
        return python
    if not python.is_file():
        venv.create(where, with_pip=True, clear=force)
    pip = [str(python), "-m", "pip", "--disable-pip-version-check", "-q"]
    subprocess.run([*pip, "install", *DEPENDENCIES], check=True)
    subprocess.run([*pip, "install", "--no-deps", MEDIAPIPE], check=True)
    worker = Path(__file__).with_name("pose_worker.py")
    check = subprocess.run(
        [str(python), str(worker)], input=b"", capture_output=True, check=False, timeout=300
    )
    if check.returncode != 0 or b'"ready"' not in check.stdout:
        raise RuntimeError(
            f"the pose worker does not start in {where}: {check.stdout.decode().strip()}"
        )
    (where / STAMP).write_text(stamp_text())
    return python


def main() -> int:
    """``python -m poppy_core.sensors.pose_venv [--force]``: make the venv, print where."""
    try:
        python = make(force="--force" in sys.argv[1:])
    except (subprocess.CalledProcessError, RuntimeError, OSError) as exc:
        print(f"pose venv: {exc}", file=sys.stderr)
        return 1
    print(f"pose venv: {python.parent.parent} ({MEDIAPIPE})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
