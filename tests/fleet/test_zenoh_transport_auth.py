"""Zenoh's own transport security from `--zenoh-config`: with user/password authentication
(Zenoh's ``usrpwd``), or with TLS (a certificate of the classroom's CA), a peer without the
credentials cannot join the robot's network: it sees no robot and reads no state. Loopback
only, scouting off in every configuration."""

from __future__ import annotations

import json
import shutil
import subprocess
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import pytest

from poppy_core import from_profile
from poppy_core.assembly import ServeSpec, ZenohSettings, serve
from poppy_core.errors import ConfigError
from poppy_core.remote.zenoh_fleet import Fleet
from poppy_core.zenoh_wire import ZenohSettings as Settings
from tests.helpers.cli import run_poppy
from tests.helpers.waiting import eventually
from tests.helpers.zenoh_served import TOKEN, fleet_timeout_s, free_endpoint

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


def _side_by_side(*checks: Callable[[], None]) -> None:
    """Run ``checks`` in threads at once, then raise the first failure: each waits out a link
    that never comes (the fleet's timeout, scaled by the load), side by side rather than one
    after the other."""
    with ThreadPoolExecutor(len(checks)) as pool:
        for future in [pool.submit(check) for check in checks]:
            future.result()


def _refused_at(door: str) -> Callable[[], None]:
    """A session without a file is the robot's Zenoh client: refused at ``door``, it never
    opens."""

    def check() -> None:
        with pytest.raises(ConfigError, match="no Zenoh router or robot answers"):
            Fleet(Settings(connect=(door,)), timeout_s=fleet_timeout_s())

    return check


def _sees_nothing(stranger: Settings) -> Callable[[], None]:
    """A peer with ``stranger``'s settings is not linked, sees no robot and gets no state."""

    def check() -> None:
        with Fleet(stranger, timeout_s=fleet_timeout_s()) as outsider:
            got = threading.Event()
            outsider.on_state(lambda name, state: got.set())
            assert not list(outsider.session.info.peers_zid())  # not linked at all
            assert outsider.names() == []
            assert not got.wait(1.0)  # 50 states a second flow to the teacher meanwhile
            assert outsider.describe() == {}

    return check


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
        with Fleet(
            Settings(connect=(endpoint,), config_file=teacher),
            token=TOKEN,
            timeout_s=fleet_timeout_s(),
        ) as fleet:
            assert fleet.wait_for(["jr-s"]) == ["jr-s"]
            states: list[int] = []
            fleet.on_state(lambda name, state: states.append(state.seq))
            assert eventually(lambda: len(states) >= 3)
        result = run_poppy(
            "fleet", "list", "--json", "--zenoh-config", str(teacher), "--zenoh-connect", endpoint
        )
        assert result.code == 0, result.stderr
        assert [row["name"] for row in result.json()] == ["jr-s"]
        # with nothing else to reach, a session without a file is the robot's Zenoh client
        _side_by_side(
            _refused_at(endpoint),
            _sees_nothing(Settings(connect=(endpoint,), mode="peer")),
            _sees_nothing(Settings(connect=(endpoint,), config_file=wrong)),
        )


def _openssl(*args: str | Path) -> None:
    subprocess.run(["openssl", *map(str, args)], check=True, capture_output=True, timeout=60)


def _certificates(folder: Path) -> tuple[Path, Path, Path]:
    """A throwaway CA and a server certificate it signed for 127.0.0.1 and localhost (EC P-256,
    a day): the CA's certificate, the server's private key and its certificate."""
    folder.mkdir()
    ca, ca_key = folder / "ca.pem", folder / "ca-key.pem"
    key, csr, cert = folder / "robot-key.pem", folder / "robot.csr", folder / "robot.pem"
    ec = ("-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes")
    _openssl(
        "req",
        "-x509",
        *ec,
        "-keyout",
        ca_key,
        "-out",
        ca,
        "-days",
        "1",
        "-subj",
        "/CN=poppy test CA",
        "-addext",
        "basicConstraints=critical,CA:TRUE",
        "-addext",
        "keyUsage=critical,keyCertSign,cRLSign",
    )
    _openssl("req", *ec, "-keyout", key, "-out", csr, "-subj", "/CN=localhost")
    extensions = folder / "robot.ext"
    extensions.write_text(
        "basicConstraints=critical,CA:FALSE\n"
        "subjectAltName=IP:127.0.0.1,DNS:localhost\n"
        "keyUsage=critical,digitalSignature\n"
        "extendedKeyUsage=serverAuth,clientAuth\n",
        encoding="utf-8",
    )
    _openssl(
        "x509",
        "-req",
        "-in",
        csr,
        "-CA",
        ca,
        "-CAkey",
        ca_key,
        "-set_serial",
        "1",
        "-days",
        "1",
        "-out",
        cert,
        "-extfile",
        extensions,
    )
    return ca, key, cert


def _tls_config(path: Path, tls: dict[str, str], listen: tuple[str, ...] = ()) -> Path:
    """A Zenoh JSON5 configuration: a peer, scouting off, with these ``transport.link.tls``
    settings, listening on ``listen``."""
    config = {
        "mode": "peer",
        "scouting": {"multicast": {"enabled": False}, "gossip": {"enabled": False}},
        "listen": {"endpoints": list(listen)},
        "transport": {"link": {"tls": tls}},
    }
    path.write_text(json.dumps(config, indent=2), encoding="utf-8")
    return path


def test_over_tls_a_peer_without_the_classrooms_ca_cannot_join_nor_read_the_state(
    moves: Path, tmp_path: Path
) -> None:
    if shutil.which("openssl") is None:
        pytest.skip("the openssl command (to make the test's CA and certificate) is not installed")
    ca, key, cert = _certificates(tmp_path / "pki")
    other_ca, _, _ = _certificates(tmp_path / "other-pki")
    endpoint = free_endpoint().replace("tcp/", "tls/", 1)
    robot_tls = {"listen_private_key": str(key), "listen_certificate": str(cert)}
    robot_config = _tls_config(tmp_path / "robot.json5", robot_tls, listen=(endpoint,))
    teacher = _tls_config(tmp_path / "teacher.json5", {"root_ca_certificate": str(ca)})
    own_ca = _tls_config(tmp_path / "own-ca.json5", {"root_ca_certificate": str(other_ca)})
    spec = ServeSpec(zenoh=ZenohSettings(config_file=robot_config), name="jr-t", token=TOKEN)
    with from_profile("ergo-jr", sim=True) as robot, serve(robot, spec):
        with Fleet(
            Settings(connect=(endpoint,), config_file=teacher),
            token=TOKEN,
            timeout_s=fleet_timeout_s(),
        ) as fleet:
            assert fleet.wait_for(["jr-t"]) == ["jr-t"]
            states: list[int] = []
            fleet.on_state(lambda name, state: states.append(state.seq))
            assert eventually(lambda: len(states) >= 3)
        result = run_poppy(
            "fleet", "list", "--json", "--zenoh-config", str(teacher), "--zenoh-connect", endpoint
        )
        assert result.code == 0, result.stderr
        assert [row["name"] for row in result.json()] == ["jr-t"]
        plain = endpoint.replace("tls/", "tcp/", 1)
        # a session without a file is the robot's Zenoh client: refused at the door, over TLS
        # (no CA: the robot's certificate is not trusted) as over plain TCP (no TLS handshake)
        _side_by_side(
            _refused_at(endpoint),
            _refused_at(plain),
            _sees_nothing(Settings(connect=(endpoint,), mode="peer")),  # TLS, no CA
            _sees_nothing(Settings(connect=(endpoint,), config_file=own_ca)),  # TLS, its own CA
            _sees_nothing(Settings(connect=(plain,), mode="peer")),  # plain TCP at the TLS port
        )


# Zenoh's access control on the robot, per user: teachers do anything under poppy/**; pupils
# see which robots are there and watch their states, nothing else (no description, no api).
_EVERYTHING = ["put", "delete", "declare_subscriber", "query", "reply", "declare_queryable"]
_LIVELINESS = ["liveliness_token", "liveliness_query", "declare_liveliness_subscriber"]
ACCESS_CONTROL: dict[str, Any] = {
    "enabled": True,
    "default_permission": "deny",
    "rules": [
        {
            "id": "all",
            "permission": "allow",
            "flows": ["egress", "ingress"],
            "messages": _EVERYTHING + _LIVELINESS,
            "key_exprs": ["poppy/**"],
        },
        {
            "id": "presence",
            "permission": "allow",
            "flows": ["egress", "ingress"],
            "messages": ["reply", *_LIVELINESS],
            "key_exprs": ["poppy/*"],
        },
        {
            "id": "states",
            "permission": "allow",
            "flows": ["egress", "ingress"],
            "messages": ["put", "declare_subscriber"],
            "key_exprs": ["poppy/*/state"],
        },
    ],
    "subjects": [
        {"id": "teachers", "usernames": ["teacher"]},
        {"id": "pupils", "usernames": ["pupil"]},
    ],
    "policies": [
        {"rules": ["all"], "subjects": ["teachers"]},
        {"rules": ["presence", "states"], "subjects": ["pupils"]},
    ],
}


def test_access_control_lets_a_pupil_watch_the_states_but_not_query_the_robot(
    moves: Path, tmp_path: Path
) -> None:
    users = tmp_path / "users.txt"
    users.write_text("teacher:classroom-pw\npupil:pupil-pw\njr-s:robot-pw\n", encoding="utf-8")
    robot_config = _config(tmp_path / "robot.json5", "jr-s", "robot-pw", dictionary_file=str(users))
    config = json.loads(robot_config.read_text(encoding="utf-8"))
    robot_config.write_text(json.dumps(config | {"access_control": ACCESS_CONTROL}), "utf-8")
    teacher = _config(tmp_path / "teacher.json5", "teacher", "classroom-pw")
    pupil = _config(tmp_path / "pupil.json5", "pupil", "pupil-pw")
    endpoint = free_endpoint()
    spec = ServeSpec(
        zenoh=ZenohSettings(listen=(endpoint,), config_file=robot_config), name="jr-s", token=TOKEN
    )
    with from_profile("ergo-jr", sim=True) as robot, serve(robot, spec):
        with Fleet(
            Settings(connect=(endpoint,), config_file=teacher),
            token=TOKEN,
            timeout_s=fleet_timeout_s(),
        ) as fleet:
            assert fleet.wait_for(["jr-s"]) == ["jr-s"]
            assert fleet.describe()["jr-s"]["name"] == "jr-s"
            (motors,) = fleet.command(["jr-s"], "GET", "/api/v1/motors", together=False)
            assert motors.ok, motors.message
        # the pupil has the token, but access control stops its queries at the robot
        with Fleet(
            Settings(connect=(endpoint,), config_file=pupil),
            token=TOKEN,
            timeout_s=fleet_timeout_s(),
        ) as watcher:
            assert watcher.wait_for(["jr-s"]) == ["jr-s"]
            states: list[int] = []
            watcher.on_state(lambda name, state: states.append(state.seq))
            assert eventually(lambda: len(states) >= 3)
            assert watcher.describe() == {}
            (refused,) = watcher.command(["jr-s"], "GET", "/api/v1/motors", together=False)
            assert not refused.ok
            # no answer at all: access control keeps the api from the pupil
            assert refused.status == 0
