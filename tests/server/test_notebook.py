"""`poppy notebook` and the "Discover your robot" notebook it ships.

The notebook runs top to bottom with nbclient (a real IPython kernel) against a virtual Ergo Jr
served over HTTP, reached as the kernel of `poppy notebook` reaches it (``POPPY_ROBOT_URL``);
the robot's state then shows what the cells did. The command itself is checked in this process
(Jupyter's start replaced by a recorder) and once for real, in a subprocess on loopback.
"""

from __future__ import annotations

import importlib.util
import json
import os
import signal
import socket
import subprocess
import sys
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from poppy_cli.commands import notebook as notebook_cmd
from tests.helpers.cli import POPPY, command_env, run_poppy
from tests.helpers.processes import reap
from tests.helpers.server import Served, serve
from tests.helpers.waiting import eventually, scaled

# found, not imported: nbformat's import (jsonschema's grammars) costs 2 s of CPU, which every
# test process would pay at collection; the one test running the notebook imports them
for _name in ("nbformat", "nbclient"):
    if importlib.util.find_spec(_name) is None:
        pytest.skip(f"could not import {_name!r}", allow_module_level=True)

NOTEBOOK = Path(notebook_cmd.__file__).parents[1] / "notebooks" / "discover-your-robot.ipynb"


@pytest.fixture
def jupyter_dirs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> dict[str, str]:
    """Jupyter's config, data and runtime folders of the test's own."""
    dirs = {
        name: str(tmp_path / "jupyter" / name.lower())
        for name in ("JUPYTER_CONFIG_DIR", "JUPYTER_DATA_DIR", "JUPYTER_RUNTIME_DIR")
    }
    for name, value in dirs.items():
        monkeypatch.setenv(name, value)
    return dirs


@pytest.fixture
def served_robot(moves_folder: str) -> Iterator[Served]:
    yield from serve(moves_folder)


def _text(cell: Any) -> str:
    """What a code cell printed or showed."""
    parts = []
    for output in cell.get("outputs", []):
        parts.append(output.get("text", ""))
        parts.append(output.get("data", {}).get("text/plain", ""))
    return "".join(parts)


def test_discover_your_robot_runs_top_to_bottom_on_a_served_ergo_jr(
    served_robot: Served, jupyter_dirs: dict[str, str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import nbclient
    import nbformat

    robot = served_robot.robot
    monkeypatch.setenv("POPPY_ROBOT_URL", served_robot.url)  # as `poppy notebook` sets it
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    client = nbclient.NotebookClient(notebook, timeout=120, kernel_name="python3")
    client.execute()  # raises CellExecutionError at the first cell that fails
    cells = {cell["id"]: cell for cell in notebook.cells if cell["cell_type"] == "code"}
    shown = {key: _text(cell) for key, cell in cells.items()}
    assert all(f"m{i} {i} XL-320" in shown["discover-04"] for i in range(1, 7))
    assert "['m1', 'm2', 'm3']" in shown["discover-05"]
    assert shown["discover-07"].strip() == "False"  # stiff
    assert shown["discover-09"].strip() == "30"  # robot.m1.goal_position = 30
    assert shown["discover-11"].strip() == "-20"  # goto_position(-20, 2, wait=True)
    assert json.loads(shown["discover-13"].replace("'", '"')) == {"m2": 10, "m3": -15, "m5": 20}
    assert "dance" in shown["discover-15"]
    assert shown["discover-16"].strip() == "True" and shown["discover-17"].strip() == "False"
    # the robot's state: the last cell's rest pose, m6 at 15, every motor free again
    assert robot.compliant and not robot.dance.is_alive()
    assert abs(robot.m6.present_position - 15) < 2
    assert all(abs(robot.motor(f"m{i}").present_position) < 2 for i in range(1, 6))


def test_the_command_adds_the_notebook_once_and_starts_jupyter_for_the_robot(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    started: list[tuple[list[str], dict[str, str]]] = []

    def recorded(args: list[str], env: dict[str, str]) -> None:
        started.append((list(args), env))
        raise SystemExit(0)

    monkeypatch.setattr(notebook_cmd, "run_jupyter", recorded)
    monkeypatch.setattr(notebook_cmd, "running_as_root", lambda: False)
    folder = tmp_path / "notebooks"
    args = ["notebook", "--dir", str(folder), "--no-browser", "--port", "8899"]
    done = run_poppy(*args, "--robot", "http://poppy.local:8080/", "--host", "0.0.0.0")
    assert done.code == 0, done.stderr
    first = folder / notebook_cmd.FIRST_NOTEBOOK
    assert first.read_bytes() == NOTEBOOK.read_bytes()
    command, env = started[0]
    assert command[:3] == [sys.executable, "-m", "notebook"]
    assert "--ServerApp.ip=0.0.0.0" in command and "--ServerApp.port=8899" in command
    assert f"--ServerApp.root_dir={folder}" in command and "--no-browser" in command
    assert env["POPPY_ROBOT_URL"] == "http://poppy.local:8080"
    first.write_text("my own edits")  # the user's notebook is theirs
    assert run_poppy("notebook", "--dir", str(folder)).code == 0
    assert first.read_text() == "my own edits"
    assert "--no-browser" not in started[1][0]
    assert started[1][1]["POPPY_ROBOT_URL"] == notebook_cmd.DEFAULT_ROBOT


def test_as_root_jupyter_gets_allow_root_and_the_user_is_told(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    started: list[list[str]] = []

    def recorded(args: list[str], env: dict[str, str]) -> None:
        started.append(list(args))
        raise SystemExit(0)

    monkeypatch.setattr(notebook_cmd, "run_jupyter", recorded)
    for root in (True, False):
        monkeypatch.setattr(notebook_cmd, "running_as_root", lambda root=root: root)
        done = run_poppy("notebook", "--dir", str(tmp_path / "nb"), "--no-browser")
        assert done.code == 0, done.stderr
        assert ("--allow-root" in started[-1]) is root
        assert ("running as root" in done.stderr) is root, done.stderr


def test_bad_input_is_one_line_and_a_missing_extra_names_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(notebook_cmd, "run_jupyter", lambda args, env: pytest.fail("started"))
    (tmp_path / "file").write_text("")
    for args, says in [
        (["--robot", "poppy.local"], "is not a robot's URL"),
        (["--robot", "http://poppy.local:8080/api"], "without a path"),
        (["--robot", "http://poppy.local:99999"], "is not a robot's URL"),
        (["--port", "0"], "--port"),
        (["--dir", str(tmp_path / "file")], "not a folder"),
    ]:
        done = run_poppy("notebook", *args)
        assert done.code != 0 and says in done.stderr, (args, done.stderr)
        assert "Traceback" not in done.stderr and len(done.stderr.strip().splitlines()) == 1
    monkeypatch.setitem(sys.modules, "notebook", None)  # as if the extra were not installed
    done = run_poppy("notebook", "--dir", str(tmp_path / "nb"))
    assert done.code != 0 and "pip install 'poppy[notebook]'" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and not (tmp_path / "nb").exists()


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def test_poppy_notebook_serves_jupyter_on_loopback(
    tmp_path: Path, jupyter_dirs: dict[str, str]
) -> None:
    port = _free_port()
    if hasattr(os, "geteuid") and os.geteuid() == 0:  # CI containers: Jupyter refuses root
        config = Path(jupyter_dirs["JUPYTER_CONFIG_DIR"])
        config.mkdir(parents=True, exist_ok=True)
        allow = {"ServerApp": {"allow_root": True}}
        (config / "jupyter_server_config.json").write_text(json.dumps(allow))
    args = ["notebook", "--port", str(port), "--dir", str(tmp_path / "nb"), "--no-browser"]
    env = dict(os.environ, **command_env(jupyter_dirs))
    proc = subprocess.Popen(
        [*POPPY, *args], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env
    )

    def answers() -> bool:
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{port}/api", timeout=5) as answer:
                return "version" in json.loads(answer.read())
        except OSError:
            return proc.poll() is not None  # ended: the assertion below says why

    try:
        assert eventually(answers, 120, 0.5)
        assert proc.poll() is None, proc.stderr.read() if proc.stderr else ""
        assert (tmp_path / "nb" / notebook_cmd.FIRST_NOTEBOOK).is_file()
        proc.send_signal(signal.SIGTERM)
        proc.wait(timeout=scaled(60))
    finally:
        reap(proc)
