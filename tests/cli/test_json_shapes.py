"""Every `--json` of the CLI has one documented shape (docs/cli.md, JSON output), whatever the
number of targets: each command runs on virtual robots and its output is checked against its
schema here; a command given `--json` without a schema here fails the test."""

from __future__ import annotations

import os
import socket
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest

from tests.helpers.bus import emulate_bus
from tests.helpers.cli import run_poppy
from tests.helpers.snap_release import make_release

# -- a small schema language: a dict is an object with exactly these keys ("key?": optional,
# "*": any other key with this schema); [S] a list of S; Map(S) an object whose keys are data
# (a register's changes, a loop's rate); Opt(S) S or null; a type is a JSON scalar.


class Map:
    def __init__(self, values: Any) -> None:
        self.values = values


class Opt:
    def __init__(self, schema: Any) -> None:
        self.schema = schema


ANY = object()
NUM = (int, float)


def problems(data: Any, schema: Any, where: str = "$") -> Iterator[str]:
    """Where ``data`` does not follow ``schema``."""
    if schema is ANY:
        return
    if isinstance(schema, Opt):
        if data is not None:
            yield from problems(data, schema.schema, where)
    elif isinstance(schema, Map):
        if not isinstance(data, dict):
            yield f"{where}: an object expected, got {data!r}"
            return
        for key, value in data.items():
            yield from problems(value, schema.values, f"{where}.{key}")
    elif isinstance(schema, list):
        if not isinstance(data, list):
            yield f"{where}: a list expected, got {data!r}"
            return
        for index, item in enumerate(data):
            yield from problems(item, schema[0], f"{where}[{index}]")
    elif isinstance(schema, dict):
        if not isinstance(data, dict):
            yield f"{where}: an object expected, got {data!r}"
            return
        keys = {key.rstrip("?"): key.endswith("?") for key in schema if key != "*"}
        for key, optional in keys.items():
            if key not in data and not optional:
                yield f"{where}: no {key!r}"
        for key, value in data.items():
            if key in keys:
                sub = schema[key + "?" if keys[key] else key]
            elif "*" in schema:
                sub = schema["*"]
            else:
                yield f"{where}: unexpected key {key!r}"
                continue
            yield from problems(value, sub, f"{where}.{key}")
    else:
        scalar = schema if isinstance(schema, tuple) else (schema,)
        if (isinstance(data, bool) and bool not in scalar) or not isinstance(data, scalar):
            yield f"{where}: {data!r} is not {schema}"


# -- the shapes -------------------------------------------------------------------------------

SETUP = {
    "operation": str,
    "port": str,
    "id": int,
    "baud": int,
    "protocol": int,
    "changes": Map([ANY]),
    "verified": bool,
    "notes": [str],
}
MOTOR_STATE = {
    "name": str,
    "id": int,
    "model": str,
    "position": NUM,
    "goal": NUM,
    "speed": NUM,
    "load": NUM,
    "temperature": NUM,
    "voltage": NUM,
    "compliant": bool,
    "online": bool,
    "errors": int,
}
BUS = {
    "name": str,
    "controller": str,
    "port": str,
    "connected": bool,
    "running": bool,
    "down_s": NUM,
    "losses": int,
    "loop_hz": Map(NUM),
    "target_hz": Map(NUM),
    "loop_errors": int,
    "timeouts": int,
    "retries": int,
    "corrupt_packets": int,
    "motor_errors": int,
    "offline": [str],
    "ok": bool,
    "label": str,
}
PRIMITIVE = {
    "name": str,
    "class": str,
    "state": str,
    "alive": bool,
    "elapsed_s": NUM,
    "properties": Map(ANY),
    "methods": [str],
    "error": Opt(Map(ANY)),
}
MS = {"p50": Opt(NUM), "p99": Opt(NUM), "max": Opt(NUM)}
XYZ = [NUM]
FLEET_OUTCOMES = [{"name": str, "ok": bool, "status": int, "message": str, "late_s": NUM}]

SCHEMAS: dict[str, Any] = {
    "fleet list": [
        {
            "name": str,
            "creature": str,
            "motors": int,
            "health": str,
            "host": str,
            "endpoints": [str],
        }
    ],
    "fleet run": FLEET_OUTCOMES,
    "fleet play": FLEET_OUTCOMES,
    "fleet stop": FLEET_OUTCOMES,
    "ports": [
        {
            "device": str,
            "description": str,
            "usb_id": Opt(str),
            "serial_number": Opt(str),
            "adapter": Opt(str),
            "latency_timer_ms": Opt(int),
            "accessible": bool,
            "advice": [str],
        }
    ],
    "scan": [
        {
            "port": str,
            "baud": int,
            "protocol": int,
            "id": int,
            "model": Opt(str),
            "model_number": int,
            "firmware": Opt(int),
        }
    ],
    "snap download": {
        "version": str,
        "path": str,
        "digest": str,
        "source": str,
        "archive_sha256": Opt(str),
        "downloaded": bool,
    },
    "record": {"path": str, "frames": int, "duration_s": NUM, "framerate": NUM, "motors": [str]},
    "dataset record": {
        "root": str,
        "repo_id": str,
        "saved": [{"episode": int, "frames": int, "duration_s": NUM}],
        "frames": int,
        "dropped": int,
        "total_episodes": int,
    },
    "dataset info": {
        "root": str,
        "codebase_version": str,
        "robot_type": Opt(str),
        "fps": int,
        "episodes": int,
        "frames": int,
        "duration_s": NUM,
        "tasks": [str],
        "cameras": [str],
        "joints": [str],
    },
    "dataset list": [{"episode": int, "frames": int, "duration_s": NUM, "tasks": [str]}],
    "dataset view": {
        "root": str,
        "episode": int,
        "frames": int,
        "mcap?": str,
        "messages?": Map(int),
        "rerun?": str,
        "rows?": Map(int),
    },
    "dataset replay": {
        "root": str,
        "episode": int,
        "frames": int,
        "motors": [str],
        "speed": NUM,
        "duration_s": NUM,
        "played_s": NUM,
        "completed": bool,
    },
    "dataset delete-episode": {
        "root": str,
        "deleted": int,
        "frames": int,
        "total_episodes": int,
        "total_frames": int,
        "total_tasks": int,
    },
    "play": {
        "path": str,
        "motors": [str],
        "speed": NUM,
        "reverse": bool,
        "loops": int,
        "duration_s": NUM,
        "played_s": NUM,
        "completed": bool,
    },
    "calibrate": {
        "profile": str,
        "path": str,
        "backup": Opt(str),
        "calibrated": str,
        "joints": [{"name": str, "offset": NUM, "angle_limit": XYZ}],
    },
    "calibrate --check": {
        "calibrated": Opt(str),
        "tolerance_deg": Opt(NUM),
        "drifted": [str],
        "joints": [{"name": str, "expected": NUM, "measured": NUM, "drift": NUM, "ok": bool}],
    },
    "teleop": {
        "leader": str,
        "follower": str,
        "map": str,
        "rate_hz": NUM,
        "duration_s": NUM,
        "ticks": int,
        "measured_hz": NUM,
        "missed_periods": int,
        "holds": int,
        "read_ms": MS,
        "pipeline_ms": MS,
        "record_path": Opt(str),
        "recorded_frames": int,
    },
    "motor info": {
        "id": int,
        "model": str,
        "model_number": int,
        "firmware": int,
        "port": str,
        "baud": int,
        "protocol": int,
        "registers": [
            {
                "name": str,
                "value": ANY,
                "unit": str,
                "address": int,
                "access": str,
                "memory": str,
            }
        ],
    },
    "motor get": [{"id": int, "*": ANY}],
    "motor set": [{"id": int, "*": ANY}],
    "motor torque": [{"id": int, "torque_enable": bool}],
    "motor led": [{"id": int, "led": (str, bool)}],
    "motor set-id": SETUP,
    "motor set-baudrate": SETUP,
    "motor set-return-delay": [SETUP],
    "motor angle-limits": [{"id": int, "min": NUM, "max": NUM}],
    "motor reboot": [SETUP],
    "motor factory-reset": SETUP,
    "motor reset": SETUP,
    "setup motors": [
        {
            "motor": str,
            "found": {"id": int, "baud": int, "protocol": int, "model": Opt(str)},
            "changes": Map([ANY]),
            "skipped": bool,
            "next": Opt(str),
        }
    ],
    "doctor": {
        "ok": bool,
        "checks": [{"name": str, "status": str, "detail": str, "fix": Opt(str)}],
    },
    # pypot's config format, as a config file holds it (keyed by name, as pypot reads it)
    "config show": {
        "controllers": Map({"attached_motors": [str], "*": ANY}),
        "motorgroups": Map([str]),
        "motors": Map({"id": int, "type": str, "*": ANY}),
        "*": ANY,
    },
    "config list": [{"name": str, "kind": Opt(str), "description": str, "user": bool, "file": str}],
    # the user settings: a fixed set of keys, each unset (null) or its value
    "config get": {"profile": Opt(str), "port": Opt(str)},
    "config path": {"settings": str, "user_profiles": str, "profile_folders": [str]},
    "robot status": {"motors": [MOTOR_STATE], "buses": [BUS]},
    "robot goto": {"motors": [{"name": str, "goal": NUM, "position": NUM}], "waited": bool},
    "robot compliant": [{"name": str, "compliant": bool}],
    "robot where": [
        {
            "name": str,
            "label": str,
            "position": XYZ,
            "orientation": XYZ,
            "rpy_deg": XYZ,
            "motors": [{"name": str, "position": NUM}],
        }
    ],
    "robot reach": {
        "chain": str,
        "label": str,
        "target": XYZ,
        "motors": [{"name": str, "goal": NUM}],
        "waited": bool,
        "position": Opt(XYZ),
        "error_m?": NUM,
    },
    "primitive list": [PRIMITIVE],
    "primitive run": {**PRIMITIVE, "interrupted": bool},
    "moves list": {
        "folder": str,
        "moves": [
            {
                "name": str,
                "path": str,
                "format": str,
                "size_bytes": int,
                "frames?": int,
                "framerate?": NUM,
                "duration_s?": NUM,
                "motors?": [str],
                "error": Opt(str),
            }
        ],
    },
    "moves show": {
        "name": str,
        "path": str,
        "format": str,
        "size_bytes": int,
        "framerate": NUM,
        "frames": int,
        "duration_s": NUM,
        "motors": [str],
        "speeds": bool,
        "metadata": Map(ANY),
        "stats": [{"name": str, "*": NUM}],
    },
    "moves plot": {"move": str, "output": str},
    "moves export": {"output": str, "format": str, "size_bytes": int},
    "moves import": {"name": str, "path": str, "frames": int, "motors": [str]},
    "moves rm": {"deleted": str},
    "camera list": [{"device": str, "index": int, "name": str}],
    "fleet discover": [
        {
            "name": str,
            "host": str,
            "creature": str,
            "version": str,
            "addresses": [str],
            "ports": Map(int),
            "urls": Map(str),
            "token": bool,
        }
    ],
    "service status": [
        {
            "unit": str,
            "scope": str,
            "installed": bool,
            "enabled": Opt(str),
            "active": str,
            "sub": str,
            "pid": Opt(int),
            "path": Opt(str),
        }
    ],
    "service release": {
        "released": bool,
        "ports": [str],
        "no_motors": [{"port": str, "message": str}],
        "primitives": [str],
        "moves": [str],
    },
    "service take": {
        "released": bool,
        "ports": [str],
        "no_motors": [{"port": str, "message": str}],
    },
    "camera detect": [
        {
            "id": int,
            "family": str,
            "position": XYZ,
            "center": XYZ,
            "corners": [XYZ],
            "camera": str,
            "card": Opt(str),
            "pose?": {"rvec": XYZ, "tvec": XYZ, "distance_m": NUM},
        }
    ],
}


def commands_with_json() -> list[str]:
    """`poppy` commands that take `--json`, as `group command`."""
    import typer

    from poppy_cli.main import app

    found: list[str] = []

    def walk(command: Any, path: list[str]) -> None:
        if hasattr(command, "commands"):
            for name, sub in command.commands.items():
                walk(sub, [*path, name])
        elif any("--json" in getattr(p, "opts", ()) for p in command.params):
            found.append(" ".join(path))

    walk(typer.main.get_command(app), [])
    return found


def test_every_json_command_has_a_schema() -> None:
    have = {name.removesuffix(" --check") for name in SCHEMAS}
    assert set(commands_with_json()) == have


# -- the runs ---------------------------------------------------------------------------------

SIM = ("--sim", "--profile", "ergo-jr")
ANSWERS = "\n\ny\n\ny\ny\n"  # calibrate: as tests/cli/test_calibrate_cmd.py answers


@contextmanager
def served_on_zenoh(name: str) -> Iterator[str]:
    """A virtual Ergo Jr served on Zenoh as ``name``; yields the endpoint it listens on."""
    from poppy_core import from_profile
    from poppy_core.assembly import ServeSpec, ZenohSettings, serve

    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        endpoint = f"tcp/127.0.0.1:{sock.getsockname()[1]}"
    with from_profile("ergo-jr", sim=True) as robot:
        servers = serve(robot, ServeSpec(zenoh=ZenohSettings(listen=(endpoint,)), name=name))
        try:
            yield endpoint
        finally:
            servers.stop()


@pytest.fixture(scope="module")
def outputs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Any, ...]]:
    """Each command's run (once, in order: record before play...): name -> its result."""
    tmp = tmp_path_factory.mktemp("json")
    saved = {
        k: os.environ.get(k)
        for k in (
            "POPPY_MOVES_DIR",
            "XDG_CONFIG_HOME",
            "XDG_DATA_HOME",
            "POPPY_PROFILE",
            "POPPY_PORT",
        )
    }
    os.environ.update(POPPY_MOVES_DIR=str(tmp / "moves"), XDG_CONFIG_HOME=str(tmp / "xdg"))
    os.environ.update(XDG_DATA_HOME=str(tmp / "data"))  # `snap download` installs there
    snap = make_release(tmp / "snap")
    (tmp / "snap.zip").write_bytes(snap.data)
    os.environ.pop("POPPY_PROFILE", None)
    os.environ.pop("POPPY_PORT", None)
    results: dict[str, Any] = {}
    try:
        with (
            emulate_bus("XL-320:1-6", protocol=2) as (_, jr),
            emulate_bus("XL-320:1-6", protocol=2) as (_, follower),
            emulate_bus("MX-28:11-13", protocol=1) as (_, mx),
            emulate_bus("XL-320:1", protocol=2) as (_, kit),
            served_on_zenoh("jr-json") as zenoh_endpoint,
        ):
            on_zenoh = ("--connect", zenoh_endpoint)
            p2 = ("--port", jr, "--baud", "1000000", "--protocol", "2")
            p1 = ("--port", mx, "--baud", "1000000", "--protocol", "1")
            pypot = str(tmp / "wave.json")
            # fmt: off
            runs: dict[str, tuple[tuple[str, ...], str]] = {
                "ports": (("ports",), ""),
                "scan": (("scan", "--port", jr, "--protocol", "2", "--ids", "1-6"), ""),
                "record": (("record", "wave", *SIM, "--duration", "0.3"), ""),
                "play": (("play", "wave", *SIM), ""),
                "dataset record": (("dataset", "record", "poppy/json", "--root", str(tmp / "ds"),
                                    *SIM, "--play", "wave", "--task", "wave", "--episode-s",
                                    "0.5", "--fps", "10", "--camera", "top=dummy:64x48",
                                    "--episodes", "2", "--reset-s", "0"), ""),
                "dataset info": (("dataset", "info", str(tmp / "ds")), ""),
                "dataset list": (("dataset", "list", str(tmp / "ds")), ""),
                "dataset replay": (("dataset", "replay", "poppy/json", "--root", str(tmp / "ds"),
                                    "--episode", "1", *SIM), ""),
                "dataset view": (("dataset", "view", "poppy/json", "--root", str(tmp / "ds"),
                                  "--episode", "1", "--mcap", str(tmp / "ep1.mcap")), ""),
                "dataset delete-episode": (("dataset", "delete-episode", "poppy/json", "--root",
                                            str(tmp / "ds"), "--episode", "0"), ""),
                "calibrate": (("calibrate", *SIM, "--motors", "m1,m2"), ANSWERS),
                "calibrate --check": (("calibrate", *SIM, "--check"), "\n"),
                "teleop": (("teleop", "--leader", "ergo-jr", "--leader-port", jr, "--follower",
                            "ergo-jr", "--follower-port", follower, "--duration", "0.5"), ""),
                "motor info": (("motor", "info", "3", *p2), ""),
                "motor get": (("motor", "get", "3", "present_position", *p2), ""),
                "motor set": (("motor", "set", "3", "goal_position", "10", *p2), ""),
                "motor torque": (("motor", "torque", "3", "on", *p2), ""),
                "motor led": (("motor", "led", "3", "red", *p2), ""),
                "motor set-id": (("motor", "set-id", "13", "20", *p1), ""),
                "motor set-baudrate": (("motor", "set-baudrate", "12", "1000000", *p1), ""),
                "motor set-return-delay": (("motor", "set-return-delay", "1-2", "0", *p2), ""),
                "motor angle-limits": (("motor", "angle-limits", "1-2", *p2), ""),
                "motor reboot": (("motor", "reboot", "4", *p2), ""),
                "motor factory-reset": (("motor", "factory-reset", "5", "--yes", *p2), ""),
                "motor reset": (("motor", "reset", "11", "11", *p1), ""),
                "setup motors": (("setup", "motors", "--profile", "ergo-jr", "--port", kit,
                                  "--motors", "m1"), "\n"),
                "doctor": (("doctor", "--profile", "ergo-jr", "--port", jr), ""),
                "config show": (("config", "show", "ergo-jr"), ""),
                "config list": (("config", "list"), ""),
                "config get": (("config", "get"), ""),
                "config path": (("config", "path"), ""),
                "robot status": (("robot", "status", *SIM), ""),
                "robot goto": (("robot", "goto", "m1=10", "--duration", "0.2", *SIM), ""),
                "robot compliant": (("robot", "compliant", "off", "base", *SIM), ""),
                "robot where": (("robot", "where", *SIM), ""),
                "robot reach": (("robot", "reach", "0.1", "0", "0.12", "--duration", "0.2",
                                 *SIM), ""),
                "primitive list": (("primitive", "list", *SIM), ""),
                "primitive run": (("primitive", "run", "sinus", "--duration", "0.2", *SIM), ""),
                "moves list": (("moves", "list"), ""),
                "moves show": (("moves", "show", "wave"), ""),
                "moves plot": (("moves", "plot", "wave", "-o", str(tmp / "wave.png")), ""),
                "moves export": (("moves", "export", "wave", "-o", pypot, "--format", "pypot"),
                                 ""),
                "moves import": (("moves", "import", pypot, "--name", "again"), ""),
                "moves rm": (("moves", "rm", "again", "--yes"), ""),
                "camera list": (("camera", "list"), ""),
                "snap download": (("snap", "download", snap.version, "--from",
                                   str(tmp / "snap.zip"), "--sha256", snap.digest), ""),
                "fleet discover": (("fleet", "discover", "--timeout", "0.5", "--interface",
                                    "127.0.0.1"), ""),
                "camera detect": (("camera", "detect", "--sim", "mujoco", "--profile", "ergo-jr",
                                   "--marker", "3"), ""),
                "fleet list": (("fleet", "list", *on_zenoh), ""),
                # a move first: a primitive running drives the motors a v1 play would take
                "fleet play": (("fleet", "play", "wave", "--robots", "jr-json", *on_zenoh), ""),
                "fleet run": (("fleet", "run", "sinus", "--all", *on_zenoh), ""),
                "fleet stop": (("fleet", "stop", "--all", *on_zenoh), ""),
            }
            # fmt: on
            for name, (args, answers) in runs.items():
                results[name] = run_poppy(*args, "--json", input=answers)
            results.update(service_runs(tmp))
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
    return results


def service_runs(tmp: Path) -> dict[str, Any]:
    """`poppy service status` against a recording systemctl, release/take on a served robot."""
    from poppy_core import from_profile
    from poppy_core.assembly import Listen, ServeSpec, serve
    from tests.helpers.recording import RecordingFake

    fake = RecordingFake(tmp / "systemd")
    show = "Id=poppy.service\nLoadState=loaded\nActiveState=active\nSubState=running\n"
    results = {
        "service status": run_poppy(
            "service", "status", "--json", env=fake.env(FAKE_COMMANDS_SHOW=show)
        )
    }
    with (
        from_profile("ergo-jr", sim=True) as robot,
        serve(robot, ServeSpec(http=Listen())) as servers,
    ):
        assert servers.http is not None
        for name in ("release", "take"):
            results[f"service {name}"] = run_poppy(
                "service", name, "--remote", servers.http.url, "--json"
            )
    return results


@pytest.mark.parametrize("name", list(SCHEMAS))
def test_json_follows_its_schema(name: str, outputs: dict[str, Any]) -> None:
    result = outputs[name]
    if name == "camera detect" and result.code != 0 and "render" in result.stderr:
        pytest.skip(f"no OpenGL here: {result.stderr.strip()}")
    # doctor exits 1 when a check fails (here: no camera, no set-up motors), JSON all the same
    assert result.code in ((0, 1) if name == "doctor" else (0,)), result.stderr
    found = list(problems(result.json(), SCHEMAS[name]))
    assert not found, found


@pytest.mark.parametrize(
    ("args", "count"),
    [
        (("motor", "get", "3", "present_position"), 1),
        (("motor", "get", "2-4", "led"), 3),
        (("motor", "set", "3", "led", "on"), 1),
        (("motor", "set", "1,3", "led", "on"), 2),
    ],
)
def test_one_shape_whatever_the_number_of_motors(args: tuple[str, ...], count: int) -> None:
    with emulate_bus("XL-320:1-6", protocol=2) as (_, url):
        result = run_poppy(*args, "--port", url, "--baud", "1000000", "--protocol", "2", "--json")
    assert result.code == 0, result.stderr
    data = result.json()
    assert isinstance(data, list) and len(data) == count
    assert not list(problems(data, [{"id": int, "*": ANY}]))


def test_no_negative_zero_in_json() -> None:
    result = run_poppy("robot", "status", *SIM, "--json")
    assert result.code == 0, result.stderr
    assert "-0.0" not in result.stdout


def test_the_docs_list_every_json_command() -> None:
    docs = (Path(__file__).resolve().parents[2] / "docs" / "cli.md").read_text(encoding="utf-8")
    section = docs.split("## JSON output", 1)[1].split("\n## ", 1)[0]
    missing = [name for name in SCHEMAS if f"`{name}`" not in section]
    assert not missing, missing
