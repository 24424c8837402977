"""`poppy sim` (serve and render), `--sim mujoco`, and the reachable-space example."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from poppy_cli.options import normalise_sim_args
from tests.helpers.cli import command_env, run_poppy
from tests.helpers.waiting import scaled

ROOT = Path(__file__).resolve().parents[2]
POPPY = [sys.executable, "-m", "poppy_cli"]
NO_GL = "cannot render offscreen"


def run(
    *args: str, timeout: float = 60, env: dict[str, str] | None = None
) -> subprocess.CompletedProcess[str]:
    full = dict(os.environ, **command_env(), **(env or {}))
    return subprocess.run(
        [*POPPY, *args], capture_output=True, text=True, timeout=timeout, env=full, check=False
    )


def run_here(*args: str) -> subprocess.CompletedProcess[str]:
    """`poppy ARGS` in this process (as a fresh one would), for commands that do not render."""
    result = run_poppy(*args)
    return subprocess.CompletedProcess(args, result.code, result.stdout, result.stderr)


class SimProcess:
    """A `poppy sim ...` process; ``url`` is the first stdout line."""

    def __init__(self, *args: str, env: dict[str, str] | None = None) -> None:
        self.proc = subprocess.Popen(
            [*POPPY, "sim", *args],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        assert self.proc.stdout is not None
        self.url = self.proc.stdout.readline().strip()
        if not self.url:
            raise RuntimeError(f"poppy sim printed nothing: {self.stop()[1]}")

    def stop(self, signum: int = signal.SIGTERM) -> tuple[int, str]:
        """Stop it; its exit code and stderr."""
        if self.proc.poll() is None:
            self.proc.send_signal(signum)
        _, err = self.proc.communicate(timeout=scaled(15))
        return self.proc.returncode, err


@pytest.fixture
def sim_ergo() -> Iterator[SimProcess]:
    process = SimProcess("--profile", "ergo-jr")
    yield process
    process.stop()


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["robot", "goto", "--sim", "m1=30"], ["robot", "goto", "--sim=ideal", "m1=30"]),
        (["robot", "status", "--sim", "mujoco"], ["robot", "status", "--sim=mujoco"]),
        (["record", "x", "--sim", "ideal", "-d", "1"], ["record", "x", "--sim=ideal", "-d", "1"]),
        (["tui", "--sim"], ["tui", "--sim=ideal"]),
        (["play", "--", "--sim"], ["play", "--", "--sim"]),
        (["status", "--sim=mujoco"], ["status", "--sim=mujoco"]),
    ],
)
def test_sim_option_takes_an_optional_engine(args: list[str], expected: list[str]) -> None:
    assert normalise_sim_args(args) == expected


def test_sim_serves_a_physical_ergo_jr(sim_ergo: SimProcess) -> None:
    assert sim_ergo.url.startswith("/dev/")
    port = ("--port", sim_ergo.url, "--baud", "1000000", "--protocol", "2")
    found = run_here("scan", *port, "--json")
    assert found.returncode == 0, found.stderr
    motors = json.loads(found.stdout)
    assert sorted(m["id"] for m in motors) == [1, 2, 3, 4, 5, 6]
    assert {m["model"] for m in motors} == {"XL-320"}
    assert run_here("motor", "torque", "1", "on", *port).returncode == 0
    assert run_here("motor", "set", "1", "goal_position", "30", *port).returncode == 0
    deadline = time.monotonic() + 10
    position = None
    while time.monotonic() < deadline:  # the physics moves the joint, at up to 684 °/s
        got = run_here("motor", "get", "1", "present_position", *port, "--json")
        assert got.returncode == 0, got.stderr
        [row] = json.loads(got.stdout)
        position = row["present_position"]
        if abs(position - 30) < 2:
            break
    assert position is not None and abs(position - 30) < 2
    code, _ = sim_ergo.stop(signal.SIGTERM)
    assert code == 0


def test_robot_goto_sim_mujoco() -> None:
    result = run(
        "robot",
        "goto",
        "--sim",
        "mujoco",
        "--profile",
        "ergo-jr",
        "m1=30",
        "--duration",
        "0.5",
        "--json",
    )
    assert result.returncode == 0, result.stderr
    [m1] = json.loads(result.stdout)["motors"]
    assert m1["name"] == "m1" and abs(m1["position"] - 30) < 3


def test_sim_with_an_unknown_engine_is_a_usage_error() -> None:
    result = run_here("robot", "status", "--sim=bullet", "--profile", "ergo-jr")
    assert result.returncode == 2
    assert "--sim mujoco" in result.stderr


def test_view_without_display_says_why_and_serves() -> None:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    process = SimProcess("--profile", "ergo-jr", "--view", env=env)
    assert process.url.startswith("/dev/")
    code, err = process.stop(signal.SIGINT)
    assert code == 0
    assert "no display" in err and "DISPLAY" in err


def test_sim_without_profile_is_a_usage_error() -> None:
    result = run_here("sim")
    assert result.returncode == 2
    assert "--profile" in result.stderr


def _rendered(result: subprocess.CompletedProcess[str]) -> None:
    if NO_GL in result.stderr:
        pytest.skip(f"no OpenGL backend here: {result.stderr.strip()}")
    assert result.returncode == 0, result.stderr


def test_render_png(tmp_path: Path) -> None:
    from PIL import Image, ImageStat

    out = tmp_path / "x.png"
    _rendered(
        run(
            "sim",
            "render",
            "--profile",
            "ergo-jr",
            "--width",
            "160",
            "--height",
            "120",
            "-o",
            str(out),
        )
    )
    with Image.open(out) as image:
        assert image.size == (160, 120)
        spread = ImageStat.Stat(image.convert("L")).stddev[0]
    assert spread > 10  # a scene, not a blank image


def test_render_move_gif(tmp_path: Path) -> None:
    from PIL import Image

    from poppy_core.motion import Move, write_move

    frames = [{"m1": 60.0 * i / 10, "m2": -20.0 * i / 10} for i in range(11)]
    move_file = write_move(Move.from_frames(10, frames), tmp_path / "turn.move.json")
    out = tmp_path / "turn.gif"
    _rendered(
        run(
            "sim",
            "render",
            "--move",
            str(move_file),
            "--width",
            "96",
            "--height",
            "72",
            "-o",
            str(out),
        )
    )
    with Image.open(out) as gif:
        assert gif.size == (96, 72)
        count = int(getattr(gif, "n_frames", 1))
        assert count >= 15  # 1 s at 15 fps, plus the first pose
        gif.seek(0)
        first = gif.convert("L").tobytes()
        gif.seek(count - 1)
        last = gif.convert("L").tobytes()
    assert first != last  # the arm moved


def test_reachable_space_example(tmp_path: Path) -> None:
    out = tmp_path / "space.png"
    script = ROOT / "docs" / "examples" / "reachable_space.py"
    done = subprocess.run(
        [sys.executable, str(script), "--samples", "5", "--output", str(out)],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert "5 forearm positions" in done.stdout
    assert out.stat().st_size > 10_000
