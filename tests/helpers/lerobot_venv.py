"""LeRobot 0.4.4 in its own venv, the oracle of the dataset tests, never imported here.

``bench/setup_lerobot.sh`` makes it (``$POPPY_LEROBOT_VENV``, else ``bench/.venv-lerobot``);
``.ci/run`` calls it. Without it a test fails on CI (``CI`` set) and is skipped elsewhere.
"""

from __future__ import annotations

import json
import os
import subprocess
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from tests.helpers.json_lines import JsonChild
from tests.helpers.no_real_time import without_real_time
from tests.helpers.pypot_files import needed

ROOT = Path(__file__).resolve().parents[2]
ORACLE = ROOT / "tests" / "dataset" / "lerobot_oracle.py"


def lerobot_python() -> Path:
    """The venv's interpreter (fails on CI, skips elsewhere, without it)."""
    places = [os.environ.get("POPPY_LEROBOT_VENV"), str(ROOT / "bench" / ".venv-lerobot")]
    for place in places:
        if place and (Path(place) / ".installed").is_file():
            return Path(place) / "bin" / "python"
    needed("LeRobot 0.4.4's venv is needed: run `bash bench/setup_lerobot.sh` (about 5 GB)")


def _oracle_env(cache: Path) -> dict[str, str]:
    env = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    env["HF_HUB_OFFLINE"] = "1"  # a dataset on disk: LeRobot must never reach for the hub
    env["HF_DATASETS_CACHE"] = str(cache)
    return env


def run_oracle(*args: str, timeout: float = 600) -> dict[str, Any]:
    """One command of tests/dataset/lerobot_oracle.py in LeRobot's venv: its JSON answer."""
    env = _oracle_env(Path(args[1]).parent / "hf-cache")
    done = subprocess.run(
        [str(lerobot_python()), str(ORACLE), *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
        env=env,
        preexec_fn=without_real_time,  # LeRobot's AV1 encoder must not go SCHED_FIFO
    )
    assert done.returncode == 0, done.stderr[-3000:]
    result: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    return result


def oracle_child(cache: Path) -> JsonChild:
    """tests/dataset/lerobot_oracle.py started in LeRobot's venv for many commands (``ask``
    them as ``run_oracle``'s arguments; ``close`` it): one Python start for a test module."""
    return JsonChild(lerobot_python(), ORACLE, _oracle_env(cache))


def oracle_fixture() -> Callable[..., Iterator[JsonChild]]:
    """A module fixture (``oracle = oracle_fixture()`` in a test module): one LeRobot oracle
    process answers the module's questions (a start costs seconds of CPU: torch's imports)."""

    @pytest.fixture(scope="module")
    def oracle(tmp_path_factory: pytest.TempPathFactory) -> Iterator[JsonChild]:
        child = oracle_child(tmp_path_factory.mktemp("lerobot-oracle") / "hf-cache")
        try:
            yield child
        finally:
            child.close()

    return oracle
