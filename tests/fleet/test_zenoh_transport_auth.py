"""Zenoh's own transport security from `--zenoh-config`: with user/password authentication
(Zenoh's ``usrpwd``), a peer without the credentials cannot join the robot's network: it sees
no robot and reads no state. Loopback only, scouting off in every configuration."""

from __future__ import annotations

import json
import threading
from pathlib import Path
from typing import Any

import pytest

from poppy_core.assembly import ServeSpec, ZenohSettings, serve
from poppy_core.errors import ConfigError
from poppy_core.remote.zenoh_fleet import Fleet
from poppy_core.robot import from_profile
from poppy_core.zenoh_wire import ZenohSettings as Settings
from tests.helpers.cli import run_poppy
from tests.helpers.waiting import eventually
from tests.helpers.zenoh_served import TOKEN, free_endpoint

pytest.importorskip("zenoh")


def _config(path: Path, user: str | None = None, password: str | None = None, **auth: Any) -> Path:
    """A Zenoh JSON5 configuration: a peer, scouting off, with these usrpwd credentials."""
    usrpwd: dict[str, Any] = dict(auth)
    if user is not None:
        usrpwd |= {"user": user, "password": password}
    config: dict[str, Any] = {
        "mode": "peer",
        "scouting": {"multicast": {"enabled": False}, "gossip": {"enabled": False}},
        "listen": {"endpoints": []},
    }
    if usrpwd:
        config["transport"] = {"auth": {"usrpwd": usrpwd}}
    path.write_text(json.dumps(config, indent=2), encoding="utf-8")
    return path


def test_a_peer_without_the_credentials_cannot_join_nor_read_the_state(
    moves: Path, tmp_path: Path
) -> None:
    users = tmp_path / "users.txt"
    users.write_text("teacher:classroom-pw\njr-s:robot-pw\n", encoding="utf-8")
    robot_config = _config(tmp_path / "robot.json5", "jr-s", "robot-pw", dictionary_file=str(users))
    teacher = _config(tmp_path / "teacher.json5", "teacher", "classroom-pw")
    wrong = _config(tmp_path / "wrong.json5", "teacher", "guess")
    endpoint = free_endpoint()
    spec = ServeSpec(
        zenoh=ZenohSettings(listen=(endpoint,), config_file=robot_config), name="jr-s", token=TOKEN
    )
    with from_profile("ergo-jr", sim=True) as robot, serve(robot, spec):
        with Fleet(Settings(connect=(endpoint,), config_file=teacher), token=TOKEN) as fleet:
            assert fleet.wait_for(["jr-s"]) == ["jr-s"]
            states: list[int] = []
            fleet.on_state(lambda name, state: states.append(state.seq))
            assert eventually(lambda: len(states) >= 3)
        result = run_poppy(
            "fleet", "list", "--json", "--zenoh-config", str(teacher), "--zenoh-connect", endpoint
        )
        assert result.code == 0, result.stderr
        assert [row["name"] for row in result.json()] == ["jr-s"]
        # with nothing else to reach, a session without a file is the robot's Zenoh client:
        # refused at the door, it never opens
        with pytest.raises(ConfigError, match="no Zenoh router or robot answers"):
            Fleet(Settings(connect=(endpoint,)))
        strangers = (
            Settings(connect=(endpoint,), mode="peer"),
            Settings(connect=(endpoint,), config_file=wrong),
        )
        for stranger in strangers:
            with Fleet(stranger) as outsider:
                got = threading.Event()
                outsider.on_state(lambda name, state, got=got: got.set())
                assert not list(outsider.session.info.peers_zid())  # not linked at all
                assert outsider.names() == []
                assert not got.wait(1.0)  # 50 states a second flow to the teacher meanwhile
                assert outsider.describe() == {}
