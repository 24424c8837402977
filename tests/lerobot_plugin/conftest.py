"""Fixtures: LeRobot 0.4.4 (its venv, tests/helpers/lerobot_venv.py) with the Poppy plugin.

The venv is shared by every clone, so the plugin is never installed there: each test session
builds it from this clone into a folder of its own (``pip install --target``, no network) and
runs LeRobot with that folder and this clone first on PYTHONPATH.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from tests.helpers.cli import command_env
from tests.helpers.json_lines import JsonChild
from tests.helpers.lerobot_venv import ROOT, lerobot_python
from tests.helpers.no_real_time import without_real_time
from tests.helpers.pypot_files import needed

PLUGIN = ROOT / "plugins" / "lerobot_robot_poppy"
PROBE = Path(__file__).with_name("plugin_probe.py")
REMEMBERED_SOURCE = Path(__file__).with_name("remembered_source")
"""Its sitecustomize.py makes LeRobot's argument parser seconds of CPU cheaper a command."""
CLI_MARK = "rerun-sdk"
"""In the venv's stamp once bench/setup_lerobot.sh added LeRobot's command-line deps."""


class Running:
    """A LeRobot command line started, its output to a file (no pipe to fill while the test
    does something else); ``with`` it: killed if the test ends before ``wait``."""

    def __init__(self, command: list[str], env: dict[str, str], timeout: float) -> None:
        self.output = tempfile.TemporaryFile("w+")  # noqa: SIM115 (closed by __exit__)
        self.process = subprocess.Popen(
            command,
            stdout=self.output,
            stderr=subprocess.STDOUT,
            text=True,
            env=env,
            preexec_fn=without_real_time,  # LeRobot's AV1 encoder must not go SCHED_FIFO
        )
        self.timeout = timeout

    def wait(self) -> str:
        """Its output, asserted to end with exit code 0."""
        try:
            self.process.wait(timeout=self.timeout)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
            raise AssertionError(f"not done in {self.timeout:.0f} s:\n{self._read()}") from None
        output = self._read()
        assert self.process.returncode == 0, output[-4000:]
        return output

    def _read(self) -> str:
        self.output.seek(0)
        return self.output.read()

    def __enter__(self) -> Running:
        return self

    def __exit__(self, *exc: object) -> None:
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()
        self.output.close()


@dataclass
class LeRobot:
    """LeRobot's venv with the plugin: ``run`` one of its command lines, or ``start`` it."""

    python: Path
    env: dict[str, str]
    home: Path

    def start(self, script: str, *args: str, timeout: float = 900) -> Running:
        """``python -m lerobot.scripts.SCRIPT ARGS`` (what ``lerobot-record``... run) started:
        two that need not wait for each other run side by side. ``inspect.getsource``
        remembers its answers there (``REMEMBERED_SOURCE``): the same parser and help, parsed
        in less CPU."""
        path = f"{REMEMBERED_SOURCE}{os.pathsep}{self.env['PYTHONPATH']}"
        command = [str(self.python), "-m", f"lerobot.scripts.{script}", *args]
        return Running(command, {**self.env, "PYTHONPATH": path}, timeout)

    def run(self, script: str, *args: str, timeout: float = 900) -> str:
        """``start`` then ``wait``: its output, asserted to end with exit code 0."""
        with self.start(script, *args, timeout=timeout) as running:
            return running.wait()


@pytest.fixture(scope="session")
def lerobot(tmp_path_factory: pytest.TempPathFactory) -> LeRobot:
    python = lerobot_python()
    if CLI_MARK not in (python.parent.parent / ".installed").read_text():
        needed(
            "LeRobot's venv lacks its command-line deps and poppy's: "
            "run `bash bench/setup_lerobot.sh` again"
        )
    base = tmp_path_factory.mktemp("lerobot-plugin")
    source, site = base / "source", base / "site"
    # built from a copy: setuptools leaves build/ and *.egg-info beside the sources
    shutil.copytree(PLUGIN, source, ignore=shutil.ignore_patterns("build", "*.egg-info"))
    subprocess.run(
        [
            str(python),
            "-m",
            "pip",
            "install",
            "--quiet",
            "--disable-pip-version-check",
            "--no-deps",
            "--no-build-isolation",
            "--no-index",
            "--target",
            str(site),
            str(source),
        ],
        check=True,
        capture_output=True,
        timeout=600,
    )
    env = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    env.update(command_env())
    env.update(
        PYTHONPATH=f"{ROOT}{os.pathsep}{site}",
        HF_LEROBOT_HOME=str(base / "lerobot"),  # datasets and calibration files
        HF_HUB_OFFLINE="1",  # everything is on disk: never reach for the hub
        HF_DATASETS_CACHE=str(base / "hf-cache"),
        MUJOCO_GL=os.environ.get("MUJOCO_GL", "egl"),
    )
    return LeRobot(python, env, base / "lerobot")


@pytest.fixture(scope="session")
def probe(lerobot: LeRobot) -> Iterator[JsonChild]:
    """tests/lerobot_plugin/plugin_probe.py in LeRobot's venv, one process answering every
    question of the session (``ask("contract", ...)``): a start costs seconds of CPU."""
    child = JsonChild(lerobot.python, PROBE, lerobot.env)
    try:
        yield child
    finally:
        child.close()
