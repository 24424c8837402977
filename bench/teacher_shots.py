"""``python -m bench.teacher_shots [FOLDER]``: the figures of the teacher's page (docs/fleet.md).

Two Ergo Jrs served on Zenoh in their own processes on loopback (``poppy serve --zenoh --name
jr1 --sim mujoco``, whose camera sees, and ``--name jr2 --sim``), ``poppy fleet serve``
connected to both, all with one token; the page in Debian's chromium: the token entered, both
robots selected, a move played on both, jr1's camera asked. Writes fleet-teacher.png (desktop)
and fleet-teacher-phone.png in FOLDER (default docs/img).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import ExitStack, contextmanager

import numpy as np

from bench.procs import child, free_port
from bench.web_bench import browser

TOKEN = "s3cret-figure"
POPPY = [sys.executable, "-m", "poppy_cli"]
SEEN = """() => {
  const img = document.querySelector("#robot-jr1 .camera img");
  if (!img || img.hidden || !img.naturalWidth) return false;
  const canvas = document.createElement("canvas");
  canvas.width = 64; canvas.height = 48;
  const context = canvas.getContext("2d");
  context.drawImage(img, 0, 0, 64, 48);
  const data = context.getImageData(0, 0, 64, 48).data;
  return data.some((value, i) => i % 4 !== 3 && value > 40);
}"""
"""jr1's picture is in the page (not a first, black, frame)."""


@contextmanager
def started(args: list[str], env: dict[str, str], until: str) -> Iterator[str]:
    """``args`` in a process of its own until the block ends: the first line holding ``until``."""
    with child(args, stdout=subprocess.PIPE, env=env, stop_timeout_s=15) as proc:
        assert proc.stdout is not None
        for line in proc.stdout:
            if until in line:
                yield line.strip()
                return
        why = proc.stderr.read() if proc.stderr else ""
        raise RuntimeError(f"{' '.join(args[2:5])} did not start: {why}")


def _wave(folder: str) -> None:
    """A 20 s move of the base in the library both robots read."""
    from poppy_core.motion.move import Move
    from poppy_core.motion.move_library import save_move

    os.environ["POPPY_MOVES_DIR"] = folder
    t = np.linspace(0.0, 2 * np.pi * 4, 400)
    save_move(Move(20.0, ["m1"], (25 * np.sin(t)).reshape(-1, 1)), "wave")


def _look_over_the_table(endpoints: list[str]) -> None:
    """Both robots' heads raised (jr1's camera sees the table's edge and the floor)."""
    from poppy_core.remote.zenoh_fleet import Fleet
    from poppy_core.zenoh_wire import ZenohSettings

    pose = {"m1": 0, "m2": -20, "m3": 30, "m4": 0, "m5": 20, "m6": 0}
    with Fleet(ZenohSettings(connect=tuple(endpoints)), token=TOKEN) as fleet:
        names = ["jr1", "jr2"]
        fleet.command(names, "PUT", "/api/v1/robot/compliant", {"compliant": False}, together=False)
        body = {"positions": pose, "duration_s": 0.8, "wait": True}
        fleet.command(names, "POST", "/api/v1/gotos", body, together=False, timeout_s=10)


def screenshots(folder: str) -> list[str]:
    """The page with two robots playing a move and jr1's camera shown (PNG files written)."""
    library = tempfile.TemporaryDirectory(prefix="poppy-teacher-shots-")
    _wave(library.name)
    env = {"POPPY_MOVES_DIR": library.name, "POPPY_TOKEN": TOKEN}
    endpoints = {name: f"tcp/127.0.0.1:{free_port()}" for name in ("jr1", "jr2")}
    sims = {"jr1": "mujoco", "jr2": "ideal"}
    written = []
    with ExitStack() as stack:
        for name, endpoint in endpoints.items():
            robot = [*POPPY, "serve", "--zenoh", "--name", name, "--zenoh-listen", endpoint]
            robot += ["--profile", "ergo-jr", "--sim", sims[name]]
            stack.enter_context(started(robot, env, "zenoh: poppy/"))
        teacher = [*POPPY, "fleet", "serve", "--http-port", str(free_port())]
        for endpoint in endpoints.values():
            teacher += ["--zenoh-connect", endpoint]
        url = stack.enter_context(started(teacher, env, "page: ")).split()[1]
        _look_over_the_table(list(endpoints.values()))
        chrome = stack.enter_context(browser())
        for shot, size, mobile in (("", (1280, 760), False), ("-phone", (390, 844), True)):
            context = chrome.new_context(
                viewport={"width": size[0], "height": size[1]},
                is_mobile=mobile,
                device_scale_factor=1,
            )
            page = context.new_page()
            page.goto(url)
            page.wait_for_selector("#token-dialog[open]")
            page.fill("#token-input", TOKEN)
            page.click("#token-ok")
            for name in endpoints:
                page.wait_for_selector(f"#robot-{name} .health.ok", timeout=60_000)
            if not shot:
                for _ in range(20):  # a first frame may be black: ask again
                    page.click("#robot-jr1 .camera button")
                    try:
                        page.wait_for_function(SEEN, timeout=5_000)
                        break
                    except Exception:
                        continue
            for name in endpoints:
                page.check(f"#robot-{name} input.pick")
            if not shot:
                page.select_option("#move-choice", "wave")
                page.click("#play")
                page.wait_for_selector("#robot-jr2 .doing:text('playing wave')")
            time.sleep(1.5)
            path = os.path.join(folder, f"fleet-teacher{shot}.png")
            page.screenshot(path=path, full_page=not mobile)
            written.append(path)
            context.close()
    library.cleanup()
    return written


def main() -> None:
    """``python -m bench.teacher_shots [FOLDER]``."""
    parser = argparse.ArgumentParser(prog="python -m bench.teacher_shots")
    parser.add_argument("folder", nargs="?", default="docs/img")
    for path in screenshots(parser.parse_args().folder):
        print(path)


if __name__ == "__main__":
    main()
