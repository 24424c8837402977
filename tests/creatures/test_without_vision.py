"""An Ergo Jr builds without the ``vision`` extra: its marker detector says it is unavailable.

The profile has a camera and a marker detector; without OpenCV the robot still builds (the
creature's primitives attached), the detector's health says why it is unavailable, and its
first use raises the one-line ``MissingExtraError`` naming ``vision``. Each case runs in a
child process where ``cv2`` cannot be imported, as ``tests/cli/test_missing_extras.py`` does.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

RUN = """
import json, sys
sys.modules["cv2"] = None
from poppy_core.pypot import PoppyErgoJr
from poppy_core.errors import MissingExtraError
from tests.helpers.bus import emulate_bus
from tests.helpers.waiting import http_timeout

def report(robot):
    health = {n: h.as_dict() for n, h in robot.sensor_health().items()}
    uses = {}
    for name, use in [
        ("markers", lambda: robot.marker_detector.markers),
        ("sees", lambda: robot.marker_detector.sees("caribou")),
        ("detect", lambda: robot.marker_detector.detect()),
    ]:
        try:
            use()
            uses[name] = None
        except MissingExtraError as exc:
            uses[name] = {"extra": exc.extra, "message": str(exc)}
    robot.m1.goal_position = 10.0  # the motors work meanwhile
    prims = [p.name for p in robot.primitives]
    print(json.dumps({"health": health, "uses": uses, "primitives": prims, "rest": rest(robot)}))

def rest(robot):
    import httpx
    from poppy_core.server import ServerThread, create_app

    server = ServerThread(create_app(robot)).start()
    try:
        with httpx.Client(base_url=server.url, timeout=http_timeout(20.0)) as http:
            path = "/sensors/marker_detector/registers/markers/value.json"
            markers = http.get(path)
            health = http.get("/api/v1/sensors/health").json()["marker_detector"]
        return {"status": markers.status_code, "body": markers.json(), "health": health}
    finally:
        server.stop()

if sys.argv[1] == "dummy":
    robot = PoppyErgoJr(simulator="dummy")
    try:
        report(robot)
    finally:
        robot.close()
else:
    with emulate_bus("XL-320:1-6") as (_bus, url):
        robot = PoppyErgoJr(port=url)
        try:
            report(robot)
        finally:
            robot.close()
"""


@pytest.mark.parametrize("where", ["dummy", "hardware"])
def test_an_ergo_jr_builds_without_opencv_and_its_detector_says_why(
    where: str, tmp_path: Path
) -> None:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "XDG_CONFIG_HOME": str(tmp_path)}
    done = subprocess.run(
        [sys.executable, "-c", RUN, where],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
        cwd=tmp_path,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr
    result = json.loads(done.stdout.strip().splitlines()[-1])
    detector = result["health"]["marker_detector"]
    assert detector["ok"] is False and detector["connected"] is False
    assert "cv2 is not installed" in detector["last_error"]
    assert "pip install 'poppy[vision]'" in detector["last_error"]
    for name, failure in result["uses"].items():
        assert failure is not None, name
        assert failure["extra"] == "vision"
        assert "\n" not in failure["message"]
        assert "pip install 'poppy[vision]'" in failure["message"]
    assert "marker_follow" in result["primitives"]
    served = result["rest"]  # a served robot: unavailable (503), one line naming the extra
    assert served["status"] == 503, served
    assert "pip install 'poppy[vision]'" in served["body"]["error"]
    assert served["health"]["ok"] is False and "cv2" in served["health"]["last_error"]
