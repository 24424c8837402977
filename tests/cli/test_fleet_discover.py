"""`poppy fleet discover` finds a robot announced on loopback; `poppy serve --name` and
`fleet discover` refuse bad input in one line, without a traceback."""

from __future__ import annotations

import os
import uuid

import pytest

from poppy_core import from_profile
from poppy_core.assembly import Listen, ServeSpec, serve
from tests.helpers.cli import run_poppy

pytest.importorskip("zeroconf")


def test_discover_lists_the_robot_announced() -> None:
    name = f"c{os.getpid()}-{uuid.uuid4().hex[:6]}"
    robot = from_profile("ergo-jr", sim=True)
    try:
        with serve(robot, ServeSpec(http=Listen(), name=name, announce=True)) as servers:
            assert servers.http is not None
            args = ("fleet", "discover", "--timeout", "3", "--interface", "127.0.0.1")
            listed = run_poppy(*args, "--json")
            table = run_poppy(*args)
    finally:
        robot.close()
    assert listed.code == 0, listed.stderr
    mine = [r for r in listed.json() if r["name"] == name]
    assert mine and mine[0]["creature"] == "ergo-jr"
    assert mine[0]["urls"] == {"http": f"http://{name}.local:{servers.http.port}/"}
    assert table.code == 0 and name in table.stdout and "ergo-jr" in table.stdout


@pytest.mark.parametrize(
    ("args", "code", "says"),
    [
        (("fleet", "discover", "--timeout", "0"), 2, "--timeout"),
        (("fleet", "discover", "--timeout", "nan"), 2, "--timeout"),
        (("fleet", "discover", "--timeout", "1", "--interface", "eth0"), 1, "not an IPv4"),
        (("serve", "--http", "--name", "bad name", "--sim"), 2, "not a robot name"),
        (("serve", "--http", "--name", "-poppy", "--sim"), 2, "not a robot name"),
    ],
)
def test_bad_input_is_one_line(args: tuple[str, ...], code: int, says: str) -> None:
    result = run_poppy(*args)
    assert result.code == code, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and says in lines[0]
    assert "Traceback" not in result.stderr
