"""`poppy dataset view REPO_ID --root DIR` without an export: the page serves the dataset on
127.0.0.1 and the command prints its URL (--json: one line of a documented shape); refusals
come in one line before any robot."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import httpx
import pytest

pytest.importorskip("pyarrow")
pytest.importorskip("av")

from tests.helpers.cli import command_env, no_user_settings, run_poppy
from tests.helpers.datasets import write_dataset
from tests.helpers.processes import reap
from tests.helpers.waiting import http_timeout

POPPY = [sys.executable, "-m", "poppy_cli"]
WAIT_S = 60.0
SHAPE = {
    "url": str,
    "repo_id": str,
    "root": str,
    "episode": int,
    "episodes": int,
    "profile": str,
}


@pytest.fixture
def dataset(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("HF_LEROBOT_HOME", str(tmp_path / "home"))
    no_user_settings(tmp_path, monkeypatch)
    root = tmp_path / "somewhere" / "wave"
    write_dataset(root)
    return root


def test_the_page_serves_the_dataset_and_its_url_is_printed(dataset: Path) -> None:
    command = [*POPPY, "dataset", "view", "class/wave", "--root", str(dataset), "--episode", "1"]
    env = dict(os.environ, **command_env({"COLUMNS": "300"}))
    proc = subprocess.Popen(
        [*command, "--json"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env
    )
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        summary = json.loads(line)
        assert {key: type(value) for key, value in summary.items()} == SHAPE, summary
        assert summary["repo_id"] == "class/wave" and summary["root"] == str(dataset)
        assert summary["episode"] == 1 and summary["episodes"] == 2
        assert summary["profile"] == "ergo-jr"
        base, _, fragment = summary["url"].partition("/#")
        assert base.startswith("http://127.0.0.1:") and fragment == "dataset=class/wave&episode=1"
        with httpx.Client(base_url=base, timeout=http_timeout(10.0)) as client:
            assert 'id="datasets"' in client.get("/").text
            listed = client.get("/api/v1/datasets").json()["datasets"]
            assert [(d["repo_id"], d["root"]) for d in listed] == [("class/wave", str(dataset))]
            frames = client.get("/api/v1/datasets/class/wave/episodes/1").json()["frames"]
            assert frames == 30
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=WAIT_S) == 0
    finally:
        reap(proc)


@pytest.mark.parametrize(
    ("args", "code", "message"),
    [
        (("--episode", "4"), 2, "no episode 4 in this dataset (episodes: 0 to 1)"),
        (("--profile", "ergo-jx"), 1, "ergo-jr"),
        (("--open", "--rerun", "x.rrd", "--episode", "0"), 2, "--open opens the page"),
    ],
)
def test_bad_pages_are_refused_in_one_line(
    dataset: Path, args: tuple[str, ...], code: int, message: str
) -> None:
    result = run_poppy("dataset", "view", "class/wave", "--root", str(dataset), *args)
    assert result.code == code, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], result.stderr


def test_a_dataset_of_no_known_robot_asks_for_a_profile(tmp_path: Path, dataset: Path) -> None:
    root = tmp_path / "other"
    write_dataset(root, robot_type="my-arm")
    result = run_poppy("dataset", "view", "class/other", "--root", str(root))
    assert result.code == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "give --profile" in lines[0], result.stderr
