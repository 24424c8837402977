"""`poppy calibrate`: a guided run on a virtual robot, the profile it writes, --check, refusals."""

from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path
from typing import Any

import pytest
import yaml

from tests.helpers.cli import POPPY, command_env, no_user_settings
from tests.helpers.waiting import scaled


@pytest.fixture(autouse=True)
def user_dirs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty user config folder, no default robot."""
    return no_user_settings(tmp_path, monkeypatch) / "poppy" / "profiles"


# Enter at the posture, Enter once m1 was "moved", yes keep its range (nothing moves a --sim
# robot by hand), Enter for m2, yes, yes write.
ANSWERS = "\n\ny\n\ny\ny\n"


def test_a_guided_run_writes_a_user_profile_that_profile_then_uses(
    poppy: Any, user_dirs: Path
) -> None:
    args = ("calibrate", "--sim", "--profile", "ergo-jr", "--motors", "m1,m2")
    result = poppy(*args, input=ANSWERS)
    assert result.code == 0, result.stderr
    path = user_dirs / "ergo-jr" / "profile.yaml"
    assert f"wrote {path}" in result.stdout
    assert "reference posture" in result.stderr and "arm stands straight up" in result.stderr
    data = yaml.safe_load(path.read_text())
    assert data["calibration"]["from"] == "ergo-jr"
    assert set(data["calibration"]["motors"]) == {"m1", "m2"}
    listed = poppy("config", "list", "--json").json()
    assert {"name": "ergo-jr", "user": True} in [
        {"name": p["name"], "user": p["user"]} for p in listed
    ]
    again = poppy(*args, "--json", input=ANSWERS)
    assert again.code == 0, again.stderr
    summary = again.json()
    assert summary["backup"] == str(path) + ".bak" and Path(summary["backup"]).is_file()
    check = poppy("calibrate", "--sim", "--profile", "ergo-jr", "--check", "--json", input="\n")
    assert check.code == 0, check.stderr
    report = check.json()
    assert report["calibrated"] == summary["calibrated"] and report["drifted"] == []
    assert {j["name"] for j in report["joints"]} == {f"m{i}" for i in range(1, 7)}


def test_quitting_writes_nothing(poppy: Any, user_dirs: Path) -> None:
    result = poppy("calibrate", "--sim", "--profile", "ergo-jr", input="q\n")
    assert result.code == 1
    assert result.stderr.strip().endswith("calibration cancelled: nothing was written")
    assert not user_dirs.exists()
    no = poppy("calibrate", "--sim", "--profile", "ergo-jr", "--motors", "m1", input="\n\ny\nn\n")
    assert no.code == 1 and "nothing written" in no.stderr and not user_dirs.exists()


def test_an_interrupted_calibration_leaves_the_previous_one(poppy: Any, user_dirs: Path) -> None:
    first = poppy(
        "calibrate", "--sim", "--profile", "ergo-jr", "--motors", "m1", "--yes", input="\n\ny\n"
    )
    assert first.code == 0, first.stderr
    path = user_dirs / "ergo-jr" / "profile.yaml"
    before = path.read_text()
    env = dict(os.environ, **command_env())
    proc = subprocess.Popen(
        [*POPPY, "calibrate", "--sim", "--profile", "ergo-jr"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    assert proc.stderr is not None and proc.stdin is not None
    while "Put the robot in this posture" not in proc.stderr.readline():
        assert proc.poll() is None
    proc.stdin.write("\n")  # in the posture; now moving the joints...
    proc.stdin.flush()
    time.sleep(0.5)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=scaled(20))
    assert proc.returncode == 130, err
    assert path.read_text() == before
    assert sorted(p.name for p in path.parent.iterdir()) == ["profile.yaml"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--motors", "m9"], "no motor or group 'm9'"),
        (["--motors", ","], "no motor given"),
        (["--name", "../x"], "cannot be a profile name"),
        (["--profile", "nope"], "unknown profile"),
    ],
)
def test_bad_input_is_one_line(poppy: Any, args: list[str], message: str) -> None:
    base = ["calibrate", "--sim"] + ([] if "--profile" in args else ["--profile", "ergo-jr"])
    result = poppy(*base, *args, input="q\n")
    assert result.code in (1, 2)
    assert message in result.stderr
    assert "Traceback" not in result.stderr
    if result.code == 1:
        assert len(result.stderr.strip().splitlines()) == 1


def test_help(poppy: Any) -> None:
    for command in ("calibrate", "teleop"):
        result = poppy(command, "--help")
        assert result.code == 0 and "Usage" in result.stdout
