"""pypot's ``simulator='threejs'``: the ideal virtual robot, its page with the 3D view served.

pypot's threejs simulator served the robot over HTTP for the poppy-simu page to draw; here the
robot's own page draws it (``/api/v1/model``). The page's URL is printed.
"""

from __future__ import annotations

import re

import httpx
import pytest

from poppy_core.errors import ConfigError
from poppy_core.pypot import PoppyErgoJr, PoppyHumanoid, PoppyTorso
from tests.helpers.waiting import http_timeout


@pytest.mark.parametrize(
    ("creature", "motor"),
    [(PoppyErgoJr, "m1"), (PoppyTorso, "l_shoulder_y"), (PoppyHumanoid, "l_shoulder_y")],
)
def test_threejs_serves_the_virtual_robot_and_prints_its_page(
    creature: type, motor: str, capsys: pytest.CaptureFixture[str]
) -> None:
    robot = creature(simulator="threejs", http_port=0)
    try:
        printed = capsys.readouterr().out
        found = re.search(r"3D view: (http://127\.0\.0\.1:\d+/)", printed)
        assert found, printed
        url = found.group(1)
        assert found.group(1).endswith(f":{robot.http.port}/")
        assert not any(m.compliant for m in robot.motors)  # virtual servos hold, as pypot's
        with httpx.Client(base_url=url, timeout=http_timeout(10.0)) as client:
            assert 'id="view3d"' in client.get("/").text
            model = client.get("/api/v1/model").json()
            assert motor in model["joints"]
            assert client.get(model["urdf"]).status_code == 200
    finally:
        robot.close()
    assert not robot.http.running


def test_an_unknown_simulator_names_threejs_among_the_choices() -> None:
    with pytest.raises(ConfigError, match="'threejs'"):
        PoppyErgoJr(simulator="blender")
