"""A ``ServeSpec`` checks itself: Python callers of ``serve()`` and the creature classes get the
same refusals and warnings as `poppy serve` (one line; a ValueError in Python, exit 2 in the CLI
with the flag named first). No server is bound here: every check comes before."""

from __future__ import annotations

import logging
from typing import Any

import pytest

from poppy_core.assembly import Listen, ServeSpec, pypot_creatures
from poppy_core.errors import ArgumentError
from poppy_core.pypot import PoppyErgoJr
from tests.helpers.cli import run_poppy

# (the spec's arguments, the same through `poppy serve`, the line, the flag the CLI names)
REFUSED: list[tuple[dict[str, Any], list[str], str, str]] = [
    (
        {"http": Listen(port=8765), "ws": Listen(port=8765)},
        ["--http", "--ws", "--http-port", "8765", "--ws-port", "8765"],
        "the WebSocket port 8765 is also the HTTP port: choose another port",
        "--ws-port",
    ),
    (
        {"http": Listen(port=8123), "http_alias_ports": (8123,)},
        ["--http", "--http-port", "8123", "--http-port", "8123"],
        "the HTTP port 8123 is given twice: give each port once",
        "--http-port",
    ),
    (
        {"http": Listen(port=8080), "snap": Listen(port=8080)},
        ["--http", "--snap", "--snap-port", "8080"],
        "the Snap! port 8080 is also the HTTP port: choose another port",
        "--snap-port",
    ),
    (
        {"ws": Listen(port=9100), "zmq": Listen(port=9100)},
        ["--ws", "--zmq", "--ws-port", "9100", "--zmq-port", "9100"],
        "the ZMQ port 9100 is also the WebSocket port: choose another port",
        "--zmq-port",
    ),
    (
        {"http": Listen(), "cors": ("snap.berkeley.edu",)},
        ["--http", "--cors", "snap.berkeley.edu"],
        "'snap.berkeley.edu' is not an origin: give scheme://host[:port]",
        "--cors",
    ),
    (
        {"http": Listen(), "allow_hosts": ("http://poppy.local/",)},
        ["--http", "--allow-host", "http://poppy.local/"],
        "'http://poppy.local/' is not a host name: give a name such as poppy.local",
        "--allow-host",
    ),
    (
        {"http": Listen(), "name": "jr_01"},
        ["--http", "--name", "jr_01"],
        "'jr_01' is not a robot name",
        "--name",
    ),
]


@pytest.mark.parametrize(("spec", "args", "line", "flag"), REFUSED, ids=lambda v: str(v)[:30])
def test_a_spec_refuses_in_python_with_one_line(
    spec: dict[str, Any], args: list[str], line: str, flag: str
) -> None:
    with pytest.raises(ValueError) as caught:
        ServeSpec(**spec)
    assert isinstance(caught.value, ArgumentError)
    assert line in str(caught.value) and "\n" not in str(caught.value)


@pytest.mark.parametrize(("spec", "args", "line", "flag"), REFUSED, ids=lambda v: str(v)[:30])
def test_poppy_serve_refuses_the_same_with_exit_2_naming_the_flag(
    spec: dict[str, Any], args: list[str], line: str, flag: str
) -> None:
    done = run_poppy("serve", *args, "--sim", "--profile", "ergo-jr")
    assert done.code == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {flag}: "), lines
    assert line in lines[0] and done.stdout == ""


def test_the_same_port_on_two_addresses_is_not_a_clash() -> None:
    ServeSpec(http=Listen("127.0.0.1", 8080), ws=Listen("::1", 8080))  # two sockets, no clash
    with pytest.raises(ArgumentError, match="also the HTTP port"):
        ServeSpec(http=Listen("0.0.0.0", 8080), ws=Listen("127.0.0.1", 8080))


def test_the_creature_classes_refuse_before_a_robot_is_built(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    built: list[str] = []
    monkeypatch.setattr(pypot_creatures, "from_profile", lambda *a, **k: built.append("robot"))
    for options, line in [
        ({"use_http": True, "use_ws": True, "ws_port": 8080}, "also the HTTP port"),
        ({"use_http": True, "use_snap": True, "snap_port": 8080}, "also the HTTP port"),
        ({"use_ws": True, "use_zmq": True, "zmq_port": 9009}, "also the WebSocket port"),
    ]:
        with pytest.raises(ValueError, match=line):
            PoppyErgoJr(simulator="dummy", **options)
    assert built == []


# (the spec's arguments, the same through `poppy serve`, the warning)
WARNED: list[tuple[dict[str, Any], list[str], str]] = [
    (
        {"http": Listen("0.0.0.0", 8080)},
        ["--http", "--host", "0.0.0.0"],
        "serving on 0.0.0.0 without a token: anyone who can reach this machine can move the robot",
    ),
    (
        {"zmq": Listen("0.0.0.0", 6768), "token": "t"},
        ["--zmq", "--host", "0.0.0.0", "--token", "t"],
        "serving the ZMQ API on 0.0.0.0: it has no token",
    ),
    (
        {"http": Listen(), "cors": ("*",)},
        ["--http", "--cors", "*"],
        "cors '*': every web page you open can move the robot",
    ),
]


@pytest.mark.parametrize(("spec", "args", "line"), WARNED, ids=lambda v: str(v)[:30])
def test_a_spec_warns_of_what_it_exposes(
    spec: dict[str, Any], args: list[str], line: str, caplog: pytest.LogCaptureFixture
) -> None:
    seen: list[str] = []
    ServeSpec(**spec, warn=seen.append)
    assert len(seen) == 1 and line in seen[0]
    with caplog.at_level(logging.WARNING, logger="poppy_core.assembly"):
        ServeSpec(**spec)  # without ``warn``: a WARNING of the assembly's log
    assert [r.getMessage() for r in caplog.records] == seen


@pytest.mark.parametrize(("spec", "args", "line"), WARNED, ids=lambda v: str(v)[:30])
def test_poppy_serve_warns_the_same_before_the_robot_is_built(
    spec: dict[str, Any], args: list[str], line: str
) -> None:
    # an unknown profile ends the command after the warning, before anything is bound
    done = run_poppy("serve", *args, "--profile", "no-such-robot", "--sim")
    assert done.code != 0
    assert f"warning: {line}" in " ".join(done.stderr.split()), done.stderr


def test_the_creature_classes_warn_as_the_cli_does(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    class Stop(Exception):
        pass

    def no_robot(*args: Any, **kwargs: Any) -> None:
        raise Stop

    monkeypatch.setattr(pypot_creatures, "from_profile", no_robot)
    with caplog.at_level(logging.WARNING, logger="poppy_core.assembly"), pytest.raises(Stop):
        PoppyErgoJr(simulator="dummy", use_http=True, http_host="0.0.0.0")
    assert any("0.0.0.0 without a token" in r.getMessage() for r in caplog.records)


def test_a_plain_spec_says_nothing(caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.WARNING):
        ServeSpec(http=Listen(), ws=Listen(), zmq=Listen(), snap=Listen(), name="jr")
    assert caplog.records == []
