"""A command whose extra is not installed says in one line which extra to install, exit 1.

Each case runs the CLI in a child process where the extra's modules cannot be imported
(``sys.modules[name] = None`` makes ``import name`` fail as if it were not installed).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from poppy_core.errors import MissingExtraError
from poppy_core.extras import require
from tests.helpers.bus import emulate_bus
from tests.helpers.cli import command_env
from tests.helpers.waiting import scaled

ROOT = Path(__file__).resolve().parents[2]

RUN = """
import sys
for name in sys.argv[1].split(","):
    sys.modules[name] = None
sys.argv = ["poppy", *sys.argv[2:]]
from poppy_cli.main import main
main()
"""

ROBOT = ["--sim", "--profile", "ergo-jr"]
CASES = [
    ("sim", "mujoco", ["sim", "render", "-o", "{tmp}/out.png"]),
    ("server", "fastapi,uvicorn", ["serve", "--http", *ROBOT, "--http-port", "0"]),
    ("server", "fastapi,uvicorn", ["serve", "--snap", *ROBOT, "--snap-port", "0"]),
    # said before the robot is built: no wait for a port or motors that would serve nothing
    ("zmq", "zmq", ["serve", "--zmq", "--profile", "ergo-jr", "--port", "/dev/nope"]),
    ("zmq", "zmq", ["serve", "--zmq", *ROBOT, "--zmq-port", "0"]),
    ("fleet", "zenoh", ["serve", "--zenoh", *ROBOT, "--name", "jr"]),
    ("fleet", "zenoh", ["fleet", "list", "--connect", "tcp/127.0.0.1:9"]),
    ("ros2", "rosbags", ["serve", "--ros2", *ROBOT, "--zenoh-listen", "tcp/127.0.0.1:0"]),
    ("foxglove", "foxglove", ["serve", "--foxglove", *ROBOT, "--foxglove-port", "0"]),
    ("foxglove", "foxglove", ["record", "w", *ROBOT, "-o", "{tmp}", "--mcap", "{tmp}/w.mcap"]),
    ("tui", "textual,textual_serve", ["tui"]),
    ("vision", "cv2", ["camera", "snapshot", "-o", "{tmp}/shot.png", "--device", "0"]),
    ("plot", "matplotlib", ["moves", "plot", "{tmp}/wave.json", "-o", "{tmp}/wave.png"]),
    ("appliance", "zeroconf", ["fleet", "discover", "--timeout", "0.5"]),
    ("appliance", "zeroconf", ["serve", "--http", *ROBOT, "--http-port", "0", "--announce"]),
]


@pytest.mark.parametrize(
    ("extra", "blocked", "argv"), CASES, ids=[" ".join(c[2][:2]) for c in CASES]
)
def test_a_missing_extra_is_one_line_naming_it(
    extra: str, blocked: str, argv: list[str], tmp_path: Path
) -> None:
    (tmp_path / "wave.json").write_text(
        '{"framerate": 10, "positions": {"0.0": {"m1": [0, 0]}, "0.1": {"m1": [1, 0]}}}'
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT), "XDG_CONFIG_HOME": str(tmp_path)}
    done = subprocess.run(
        [sys.executable, "-c", RUN, blocked, *(a.format(tmp=tmp_path) for a in argv)],
        capture_output=True,
        text=True,
        timeout=scaled(90),
        env=env,
        cwd=tmp_path,
        check=False,
    )
    assert done.returncode == 1, (done.stdout, done.stderr)
    assert "Traceback" not in done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert f"pip install 'poppy[{extra}]'" in lines[0]


EVERY_EXTRA = (
    "mujoco,cv2,fastapi,uvicorn,starlette,zmq,textual,textual_serve,matplotlib,skimage,PIL"
)


def _poppy_without_extras(argv: list[str], tmp_path: Path) -> subprocess.CompletedProcess[str]:
    # its motors are an emulator thread of this process: the load's reply floor (command_env)
    env = {**os.environ, **command_env({"PYTHONPATH": str(ROOT), "XDG_CONFIG_HOME": str(tmp_path)})}
    return subprocess.run(
        [sys.executable, "-c", RUN, EVERY_EXTRA, *argv],
        capture_output=True,
        text=True,
        timeout=scaled(120),
        env=env,
        cwd=tmp_path,
        check=False,
    )


def test_the_core_scans_drives_and_reports_a_robot_without_any_extra(tmp_path: Path) -> None:
    """What `pip install poppy` (no extra) gives a Raspberry Pi: a bus on a pty, a scan, a
    motor read and write, the robot's status (its profile has a camera: not opened), the demo."""
    with emulate_bus("XL-320:1-6", protocol=2, via="pty") as (_, port):
        runs = [
            ["scan", "--port", port, "--protocol", "2", "--baud", "1000000", "--json"],
            ["motor", "set", "3", "goal_position", "10", "--port", port],
            ["motor", "get", "3", "goal_position", "--port", port],
            ["robot", "status", "--profile", "ergo-jr", "--port", port, "--json"],
        ]
        done = [_poppy_without_extras(argv, tmp_path) for argv in runs]
    done.append(_poppy_without_extras(["demo", "--quick"], tmp_path))
    for argv, result in zip([*runs, ["demo"]], done, strict=True):
        assert result.returncode == 0, (argv, result.stderr)
        assert "Traceback" not in result.stderr
    assert '"id":6' in done[0].stdout.replace(" ", "")
    assert done[2].stdout.startswith("9.96 °")  # 10° on the XL-320's 0.29° steps
    assert "m6" in done[3].stdout


def test_require_names_the_extra_and_the_feature(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "mujoco", None)
    with pytest.raises(MissingExtraError) as caught:
        require("mujoco", extra="sim", feature="rendering")
    assert caught.value.extra == "sim"
    assert str(caught.value) == (
        "mujoco is not installed (used by rendering): pip install 'poppy[sim]'"
    )


def test_require_passes_when_installed() -> None:
    require("json", extra="sim")  # no error: the module imports
