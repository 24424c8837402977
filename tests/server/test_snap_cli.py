"""`poppy serve --snap` and `poppy snap`: URLs printed, options checked, files written."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import urllib.request
import xml.etree.ElementTree as ET
from pathlib import Path

from tests.helpers.cli import command_env, run_poppy
from tests.helpers.processes import start

POPPY = [sys.executable, "-m", "poppy_cli"]
TIMEOUT_S = 90


def _env(moves: Path) -> dict[str, str]:
    return dict(os.environ, **command_env(), POPPY_MOVES_DIR=str(moves))


def _get(url: str) -> str:
    with urllib.request.urlopen(url, timeout=20) as answer:
        return str(answer.read().decode())


def test_serve_snap_with_http_prints_the_snap_urls_and_serves_both(tmp_path: Path) -> None:
    snap_dir = tmp_path / "snap"
    snap_dir.mkdir()
    (snap_dir / "snap.html").write_text("<html>a local Snap!</html>")
    args = ["serve", "--http", "--http-port", "0", "--snap", "--snap-port", "0", "--ws"]
    args += ["--ws-port", "0"]
    args += ["--sim", "--profile", "ergo-jr", "--snap-dir", str(snap_dir), "--open"]
    opened = tmp_path / "opened.txt"
    browser = tmp_path / "browser.sh"  # what --open runs: $BROWSER, read by webbrowser
    browser.write_text(f'#!/bin/sh\necho "$1" > {opened}\n')
    browser.chmod(0o755)
    env = {**_env(tmp_path / "moves"), "BROWSER": f"{browser} %s"}
    proc = start([*POPPY, *args], env)
    try:
        assert proc.stdout is not None
        lines = [proc.stdout.readline().strip() for _ in range(5)]
        http_url, ws_url = lines[0], lines[1]
        snap_url = next(line for line in lines if line.startswith("snap: ")).split()[1]
        editor = next(line for line in lines if line.startswith("Snap! with the Poppy blocks: "))
        assert snap_url.startswith("http://127.0.0.1:")
        assert ws_url.startswith("ws://127.0.0.1:")
        assert (
            len(
                {
                    http_url.rsplit(":", 1)[1],
                    ws_url.rsplit(":", 1)[1].strip("/"),
                    snap_url.rsplit(":", 1)[1],
                }
            )
            == 3
        )
        assert editor.endswith(f"{snap_url}/app/snap.html#open:{snap_url}/snap-blocks.xml")
        deadline = time.monotonic() + 30
        while not opened.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        assert opened.read_text().strip() == editor.split(": ", 1)[1]
        assert _get(f"{snap_url}/motors/motors") == "m1/m2/m3/m4/m5/m6"
        assert "a local Snap!" in _get(f"{snap_url}/app/snap.html")
        assert ET.fromstring(_get(f"{snap_url}/snap-blocks.xml")).tag == "project"
        assert '"motors"' in _get(f"{http_url}/motors/list.json")
        links = json.loads(_get(f"{http_url}/api/v1/web/about"))["links"]
        assert links["Snap! with the Poppy blocks"] == editor.split(": ", 1)[1]  # the home page
        # a move recorded from Snap! is seen by the REST routes: one library
        assert _get(f"{snap_url}/primitive/MoveRecorder/from-snap/start/m1") == "Done!"
        assert _get(f"{snap_url}/primitive/MoveRecorder/from-snap/stop") == "Done!"
        assert "from-snap" in _get(f"{http_url}/records/list.json")
        assert (tmp_path / "moves").is_dir() and any((tmp_path / "moves").iterdir())
    finally:
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=TIMEOUT_S)
    assert proc.returncode == 0, err
    assert "Traceback" not in err


def _run(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    """`poppy ARGS` in this process (as a fresh one would), with its library in ``cwd/m``."""
    result = run_poppy(*args, env={"POPPY_MOVES_DIR": str(cwd / "m")})
    return subprocess.CompletedProcess(args, result.code, result.stdout, result.stderr)


def test_snap_options_are_checked_before_the_robot_is_built(tmp_path: Path) -> None:
    for args, says in [
        (["--http", "--open"], "--open needs --snap"),
        (["--http", "--snap-dir", str(tmp_path)], "--snap-dir needs --snap"),
        (["--snap", "--snap-dir", str(tmp_path)], "no snap.html there"),
        (
            ["--snap", "--http", "--snap-port", "8080"],
            "--snap-port: the Snap! port 8080 is also the HTTP port",
        ),
        (["--snap", "--cors", "snap.berkeley.edu"], "is not an origin"),
    ]:
        done = _run("serve", *args, "--sim", "--profile", "ergo-jr", cwd=tmp_path)
        assert done.returncode == 2, (args, done.stderr)
        assert says in done.stderr and len(done.stderr.strip().splitlines()) == 1, done.stderr


def test_snap_blocks_writes_the_library_and_refuses_to_overwrite(tmp_path: Path) -> None:
    target = tmp_path / "blocks.xml"
    done = _run(
        "snap",
        "blocks",
        "-o",
        str(target),
        "--profile",
        "ergo-jr",
        "--lang",
        "fr",
        "--host",
        "192.168.1.20",
        cwd=tmp_path,
    )
    assert done.returncode == 0, done.stderr
    root = ET.parse(target).getroot()
    assert root.get("name") == "poppy-blocks-fr"
    host = root.find("./variables/variable[@name='host']")
    assert host is not None and host.findtext("l") == "192.168.1.20"
    again = _run("snap", "blocks", "-o", str(target), "--profile", "ergo-jr", cwd=tmp_path)
    assert again.returncode == 1 and len(again.stderr.strip().splitlines()) == 1
    example = _run(
        "snap",
        "project",
        "record-replay",
        "-o",
        str(tmp_path),
        "--profile",
        "ergo-jr",
        cwd=tmp_path,
    )
    assert example.returncode == 0, example.stderr
    assert ET.parse(tmp_path / "record-replay.xml").getroot().get("name") == "record-replay"
    unknown = _run("snap", "project", "nope", "-o", str(tmp_path), cwd=tmp_path)
    assert unknown.returncode == 2 and "first-steps" in unknown.stderr


def test_ctrl_c_while_the_browser_opens_is_a_clean_stop(tmp_path: Path) -> None:
    # The README tour's Ctrl-C came while `--open` was starting the browser (the URLs printed):
    # the interrupt escaped as "interrupted", 130, with no `stopped`.
    started = tmp_path / "browser-started"
    browser = tmp_path / "browser.sh"  # a browser slow to start: webbrowser waits for it
    browser.write_text(f"#!/bin/sh\ntouch {started}\nsleep 5\n")
    browser.chmod(0o755)
    args = ["serve", "--snap", "--snap-port", "0", "--sim", "--profile", "ergo-jr", "--open"]
    env = {**_env(tmp_path / "moves"), "BROWSER": f"{browser} %s"}
    proc = start([*POPPY, *args], env)
    try:
        deadline = time.monotonic() + TIMEOUT_S
        while not started.exists() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert started.exists(), "the browser was never started"
    finally:
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=TIMEOUT_S)
    assert proc.returncode == 0, err
    assert "stopped" in err and "Traceback" not in err
