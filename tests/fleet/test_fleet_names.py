"""One robot name for mDNS and Zenoh (``checks.robot_name``): ``poppy serve --name NAME`` is
``NAME.local`` and ``poppy/NAME`` alike; a name one of them refuses is refused by both, before
anything connects."""

from __future__ import annotations

from pathlib import Path

import pytest

from poppy_core import zenoh_wire
from poppy_core.assembly import ServeSpec
from poppy_core.errors import ArgumentError, ConfigError
from poppy_core.remote.zenoh_client import robot_name as zenoh_url_name
from poppy_core.server.host_names import robot_names
from tests.helpers.cli import run_poppy
from tests.helpers.zenoh_served import Served, connect_to, fleet_timeout_s, free_endpoint

pytest.importorskip("zenoh")


def _mdns(name: str) -> set[str] | None:
    try:
        return robot_names(name)
    except ValueError:
        return None


def _zenoh(name: str) -> str | None:
    try:
        return zenoh_wire.check_name(name)
    except ConfigError:
        return None


@pytest.mark.parametrize(
    "name", ["poppy", "ergo-2", "Poppy", "Ergo-2.local", "jr_01", "jr.1", "-jr", "a" * 64, "x y"]
)
def test_mdns_and_zenoh_take_and_refuse_the_same_names(name: str) -> None:
    zenoh = _zenoh(name)
    mdns = _mdns(name)
    if zenoh is None:
        assert mdns is None, f"{name!r}: refused on Zenoh, taken as {mdns} on mDNS"
    else:
        assert mdns == {zenoh, f"{zenoh}.local"}, f"{name!r}: poppy/{zenoh} but {mdns}"


def test_the_served_name_is_the_one_rule_s() -> None:
    assert ServeSpec(name="Ergo-2.local").name == "ergo-2"
    with pytest.raises(ArgumentError, match=r"^name 'jr_01' is not a robot name: .*e\.g\. poppy"):
        ServeSpec(name="jr_01")
    assert zenoh_wire.robot_key("Poppy", "state") == "poppy/poppy/state"
    assert zenoh_url_name("zenoh:Poppy.local") == "poppy"


def test_the_default_zenoh_name_follows_the_rule(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(zenoh_wire.socket, "gethostname", lambda: "My_Pi.lan")
    assert zenoh_wire.default_name() == "my-pi"
    monkeypatch.setattr(zenoh_wire.socket, "gethostname", lambda: "__")
    assert zenoh_wire.default_name() == "poppy"


def test_a_robot_served_with_capitals_is_found_and_driven_lower_case(
    moves: Path,
) -> None:
    from poppy_core.remote.zenoh_fleet import Fleet
    from poppy_core.zenoh_wire import ZenohSettings

    served = Served("Jr-Mixed", token=None)
    try:
        with Fleet(ZenohSettings(connect=connect_to(served)), timeout_s=fleet_timeout_s()) as fleet:
            assert fleet.wait_for(["jr-mixed"], timeout_s=15) == ["jr-mixed"]
            (outcome,) = fleet.command(["JR-Mixed"], "GET", "/api/v1/motors", together=False)
            assert outcome.ok, outcome.message
    finally:
        served.close()


@pytest.mark.parametrize(
    "args",
    [
        ("fleet", "stop", "--robots", "jr-a,jr_01"),
        ("fleet", "run", "dance", "--robots", "bad name!"),
        ("fleet", "play", "wave", "--robots", ","),
    ],
)
def test_fleet_robots_are_checked_before_connecting(args: tuple[str, ...]) -> None:
    result = run_poppy(*args, "--connect", free_endpoint())
    assert result.code == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), lines
    assert "is not a robot name" in lines[0] or "--all, or --robots a,b" in lines[0]


@pytest.mark.parametrize("name", ["bad name!", "jr_01", "jr.1"])
def test_serve_refuses_a_name_either_side_would_refuse(name: str) -> None:
    result = run_poppy("serve", "--zenoh", "--name", name, "--sim")
    assert result.code == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: --name: "), lines
    assert f"{name!r} is not a robot name" in lines[0], lines
    assert "e.g. poppy or ergo-2" in lines[0]
