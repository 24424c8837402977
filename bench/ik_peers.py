"""Run pypot's kinematic chains (``bench/peers/pypot_ik.py``) in the peers venv on a job."""

from __future__ import annotations

import json
import subprocess
import tempfile
from pathlib import Path
from typing import Any

from bench.registry import BENCH_DIR, REPO_ROOT

PEER_SCRIPT = BENCH_DIR / "peers" / "pypot_ik.py"
URDF_FILES = {
    "ergo-jr": "poppy_ergo_jr.urdf",
    "torso": "poppy_torso.urdf",
    "humanoid": "poppy_humanoid.urdf",
}
TIMEOUT_S = 3600.0


def run_pypot_ik(python: Path, kinds: list[str], job: dict[str, Any]) -> dict[str, Any]:
    """pypot's answer to ``job`` for the creatures ``kinds`` (see the peer script's doc).

    Each creature's pypot JSON config is written from poppy's profile, so both sides use the
    same orientations, offsets and limits.

    Raises:
        RuntimeError: the peer script failed (its last error line in the message).
    """
    from poppy_core.robot import load_profile

    with tempfile.TemporaryDirectory(prefix="poppy-ik-") as tmp:
        args = []
        for kind in kinds:
            config = Path(tmp) / f"{kind}.json"
            config.write_text(json.dumps(load_profile(kind).to_pypot_dict()), encoding="utf-8")
            urdf = REPO_ROOT / "profiles" / kind / URDF_FILES[kind]
            args.append(f"{kind}={config}:{urdf}")
        done = subprocess.run(
            [str(python), str(PEER_SCRIPT), *args],
            input=json.dumps(job),
            capture_output=True,
            text=True,
            timeout=TIMEOUT_S,
            cwd=REPO_ROOT,
            check=False,
        )
    if done.returncode != 0 or not done.stdout.strip():
        tail = (done.stderr.strip().splitlines() or [f"exit {done.returncode}"])[-1]
        raise RuntimeError(f"pypot_ik.py failed: {tail}")
    result: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    return result
