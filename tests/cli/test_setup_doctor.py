"""`poppy setup motors` on a kit of six XL-320 all at ID 1, plugged one at a time, then `poppy
doctor`: all pass on the robot set up, and each fault gives its failing line with its fix."""

from __future__ import annotations

import io
import os
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import pytest

from poppy_cli.commands import doctor as doctor_cmd
from poppy_core.bus.timing import MIN_REPLY_TIMEOUT_S, REPLY_FLOOR_ENV
from poppy_core.emulator import VirtualBus, build_bus_from_spec, serve_link, serve_pty
from poppy_core.robot.doctor_system import SystemProbe
from poppy_core.robot.guided_setup import motor_targets
from poppy_core.robot.profiles import load_profile
from tests.helpers.cli import Result, no_user_settings, run_poppy

ERGO_JR = load_profile("ergo-jr")
# The environment of a command whose motors are on the in-process link (emu://): they answer in
# the writer's thread, never late, so the command keeps a real adapter's first-reply floor (the
# loaded one is waited by every ping of an ID not taken yet, several per motor set up).
ON_THE_LINK = {REPLY_FLOOR_ENV: str(MIN_REPLY_TIMEOUT_S)}


class PlugOneAtATime(io.TextIOBase):
    """stdin of `poppy setup motors`: before each Enter, the motor plugged before is taken off
    the line and the next one of the kit is put on (what the person does at each prompt)."""

    def __init__(self, bus: VirtualBus) -> None:
        self.bus = bus
        self.place = 0
        self.prompts = 0

    def readable(self) -> bool:
        return True

    def readline(self, size: int | None = -1) -> str:  # type: ignore[override]
        del size
        self.prompts += 1
        if self.place:
            self.bus.detach(self.place)
        if self.place == len(self.bus.motors):
            return ""
        self.place += 1
        self.bus.attach(self.place)
        return "\n"


def kit(spec: str = "XL-320:1*6") -> VirtualBus:
    """Motors as they come from the box: factory ID, rate and return delay, none on the line."""
    bus = build_bus_from_spec(spec, protocol=2)
    for place in range(1, len(bus.motors) + 1):
        bus.detach(place)
    return bus


@dataclass
class Machine:
    """The machine `poppy doctor` looks at: fake sysfs and /dev, a recording systemctl."""

    root: Path
    calls: list[list[str]]

    def latency(self, port: str, ms: int) -> None:
        tty = os.path.basename(os.path.realpath(port))
        folder = self.root / "sys" / "bus" / "usb-serial" / "devices" / tty
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "latency_timer").write_text(f"{ms}\n")

    def camera(self, present: bool) -> None:
        video = self.root / "dev" / "video0"
        if present:
            video.write_text("")
        else:
            video.unlink(missing_ok=True)


@pytest.fixture
def machine(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Machine:
    (tmp_path / "dev").mkdir()
    calls: list[list[str]] = []

    def systemctl(argv: Sequence[str]) -> tuple[int, str]:
        calls.append(list(argv))
        if "cat" in argv:
            return 0, "[Service]\nExecStart=/usr/bin/poppy serve --profile ergo-jr --port auto"
        return (0, "active") if "is-active" in argv else (0, "enabled")

    def fetch(url: str) -> int | None:
        calls.append(["GET", url])
        return 200

    probe = SystemProbe(
        sysfs_root=str(tmp_path / "sys"),
        dev_root=str(tmp_path / "dev"),
        run=systemctl,
        fetch=fetch,
        disk_path=tmp_path,
    )
    monkeypatch.setattr(doctor_cmd, "system_probe", lambda: probe)
    found = Machine(tmp_path, calls)
    found.camera(True)
    return found


def doctor(port: str, env: dict[str, str] | None = None) -> Result:
    return run_poppy("doctor", "--profile", "ergo-jr", "--port", port, "--json", env=env)


def failures(result: Result) -> dict[str, list[str]]:
    """Failed checks: name -> their fix lines."""
    assert result.code == 1, result.stderr
    failed = [c for c in result.json()["checks"] if c["status"] == "fail"]
    print(failed)  # shown when the test fails
    found: dict[str, list[str]] = {}
    for check in result.json()["checks"]:
        if check["status"] == "fail":
            found.setdefault(check["name"], []).append(check["fix"])
    return found


def test_a_kit_plugged_one_at_a_time_becomes_an_ergo_jr_that_doctor_passes(
    machine: Machine,
) -> None:
    bus = kit()
    # set up on the in-process link; doctor looks at the same motors on a pty (its latency timer)
    with serve_link(bus) as link, serve_pty(bus) as server:
        machine.latency(server.url, 1)
        stdin = PlugOneAtATime(bus)
        done = run_poppy(
            "setup",
            "motors",
            "--profile",
            "ergo-jr",
            "--port",
            link.url,
            input=stdin,
            env=ON_THE_LINK,
        )
        assert done.code == 0, done.stderr
        assert stdin.prompts == 6
        for name in ("m1", "m2", "m6"):
            assert f"plug only {name} (XL-320) on the bus and press Enter" in done.stderr
        assert "next: m4" in done.stderr and "all motors done" in done.stderr
        for place in range(1, 7):
            bus.attach(place)
        targets = motor_targets(ERGO_JR)
        assert [m.id for m in bus.motors] == [1, 2, 3, 4, 5, 6]
        for motor, target in zip(bus.motors, targets, strict=True):
            assert motor.baudrate_bps == 1_000_000
            assert motor.table.get("return_delay_time") == 0
            low, high = target.angle_limits
            assert motor.table.get_si("min_position_limit") == pytest.approx(low, abs=0.3)
            assert motor.table.get_si("max_position_limit") == pytest.approx(high, abs=0.3)
        report = doctor(server.url)
    assert report.code == 0, report.stdout
    checks = report.json()["checks"]
    assert report.json()["ok"] is True
    assert {c["status"] for c in checks} == {"pass"}, checks
    names = [c["name"] for c in checks]
    assert names[:3] == ["adapter", "latency timer", "duplicated IDs"]
    assert [f"m{i} (ID {i})" for i in range(1, 7)] == names[3:9]
    assert names[9:] == ["camera", "service", "page", "disk"]
    assert ["systemctl", "is-active", "poppy.service"] in machine.calls
    assert ["GET", "http://poppy.local/"] in machine.calls


def set_up_robot(spec: str = "XL-320:1-6") -> VirtualBus:
    """An Ergo Jr bus whose motors hold the profile's settings (as `poppy setup motors` left)."""
    bus = build_bus_from_spec(spec, protocol=2)
    targets = {t.id: t for t in motor_targets(ERGO_JR)}
    for motor in bus.motors:
        motor.table.set("return_delay_time", 0)
        target = targets.get(motor.id)
        if target is not None and motor.model.name == target.model:
            motor.table.set_si("min_position_limit", target.angle_limits[0])
            motor.table.set_si("max_position_limit", target.angle_limits[1])
    return bus


@pytest.fixture
def robot(machine: Machine) -> Iterator[Callable[[VirtualBus], tuple[VirtualBus, str]]]:
    """Serve a robot's bus on a pty with a good latency timer; yield (bus, port)."""
    servers = []

    def serve(bus: VirtualBus) -> tuple[VirtualBus, str]:
        server = serve_pty(bus)
        servers.append(server)
        machine.latency(server.url, 1)
        return bus, server.url

    yield serve
    for server in servers:
        server.stop()


def test_doctor_passes_a_set_up_robot(robot: Callable[..., tuple[VirtualBus, str]]) -> None:
    _, port = robot(set_up_robot())
    result = doctor(port)
    assert (result.code, result.json()["ok"]) == (0, True), result.stdout


def test_doctor_names_a_missing_motor(machine: Machine) -> None:
    """On the in-process link: doctor pings a missing motor three times at the floor, then scans
    for it, and a pty emulator needs the loaded floor."""
    bus = set_up_robot()
    bus.detach(3)
    with serve_link(bus) as server:
        fixes = failures(doctor(server.url, env=ON_THE_LINK))
    assert list(fixes) == ["m3 (ID 3)"]
    assert "poppy setup motors --profile ergo-jr" in fixes["m3 (ID 3)"][0]
    assert "--motors m3" in fixes["m3 (ID 3)"][0]


def test_doctor_says_where_a_motor_at_another_rate_answers(machine: Machine) -> None:
    """On the in-process link, which answers at once: the scan doctor runs for a missing motor
    keeps a real adapter's deadlines at every rate by design (`poppy_core.bus.scan`), and an
    emulator thread on a pty that a busy machine ran late missed them at load 8."""
    bus = set_up_robot()
    bus.motor(5).table.set("baudrate", 1)  # XL-320 code 1: 57,600 bps (e-manual)
    with serve_link(bus) as server:
        result = doctor(server.url, env=ON_THE_LINK)
    fixes = failures(result)
    assert list(fixes) == ["m5 (ID 5)"]
    detail = next(c["detail"] for c in result.json()["checks"] if c["name"] == "m5 (ID 5)")
    assert detail.endswith("; ID 5 answers at 57600 bps")
    assert "--motors m5" in fixes["m5 (ID 5)"][0]


def test_doctor_names_a_wrong_model(robot: Callable[..., tuple[VirtualBus, str]]) -> None:
    _, port = robot(set_up_robot("XL-320:1-2,XL430-W250:3,XL-320:4-6"))
    result = doctor(port)
    fixes = failures(result)
    assert list(fixes) == ["m3 (ID 3)"]
    assert fixes["m3 (ID 3)"][0].startswith("plug a XL-320 as m3")
    detail = next(c["detail"] for c in result.json()["checks"] if c["name"] == "m3 (ID 3)")
    assert detail == "ID 3 is a XL430-W250, m3 is a XL-320"


def test_doctor_finds_a_duplicated_id(robot: Callable[..., tuple[VirtualBus, str]]) -> None:
    _, port = robot(set_up_robot("XL-320:1-2,3*2,4-6"))
    result = doctor(port)
    fixes = failures(result)
    assert "duplicated IDs" in fixes
    assert fixes["duplicated IDs"][0].startswith("unplug all but one of them")
    detail = next(c["detail"] for c in result.json()["checks"] if c["name"] == "duplicated IDs")
    assert detail == "ID 3 (2 motors)"


def test_doctor_finds_a_500_us_return_delay(
    robot: Callable[..., tuple[VirtualBus, str]],
) -> None:
    bus, port = robot(set_up_robot())
    bus.motor(4).table.set("return_delay_time", 250)  # 2 µs a unit (e-manual): 500 µs
    fixes = failures(doctor(port))
    assert fixes == {"m4 (ID 4)": [f"poppy motor set-return-delay 4 0 --port {port}"]}


def test_doctor_finds_a_16_ms_latency_timer(
    robot: Callable[..., tuple[VirtualBus, str]], machine: Machine
) -> None:
    _, port = robot(set_up_robot())
    machine.latency(port, 16)
    fixes = failures(doctor(port))
    assert list(fixes) == ["latency timer"]
    tty = os.path.basename(os.path.realpath(port))
    fix = fixes["latency timer"][0]
    assert f"echo 1 | sudo tee /sys/bus/usb-serial/devices/{tty}/latency_timer" in fix
    assert 'ATTR{latency_timer}="1"' in fix


def test_doctor_finds_no_camera(
    robot: Callable[..., tuple[VirtualBus, str]], machine: Machine
) -> None:
    _, port = robot(set_up_robot())
    machine.camera(False)
    fixes = failures(doctor(port))
    assert list(fixes) == ["camera"]
    assert "`poppy camera list`" in fixes["camera"][0]


def test_doctor_prints_one_line_per_check_with_its_fix(
    robot: Callable[..., tuple[VirtualBus, str]], machine: Machine
) -> None:
    _, port = robot(set_up_robot())
    machine.latency(port, 16)
    result = run_poppy("doctor", "--profile", "ergo-jr", "--port", port)
    assert result.code == 1
    lines = result.stdout.splitlines()
    at = next(i for i, line in enumerate(lines) if line.startswith("✗ FAIL latency timer: 16 ms"))
    assert lines[at + 1].strip().startswith("fix: echo 1 | sudo tee")
    assert "✓ pass m1 (ID 1): XL-320 at 1000000 bps, firmware 45" in result.stdout
    assert lines[-1] == "1 check(s) failed"


def test_doctor_checks_the_page_by_the_name_the_service_gives(
    robot: Callable[..., tuple[VirtualBus, str]], monkeypatch: pytest.MonkeyPatch
) -> None:
    _, port = robot(set_up_robot())
    probe = doctor_cmd.system_probe()
    asked: list[str] = []

    def user_unit(argv: Sequence[str]) -> tuple[int, str]:
        if "--user" not in argv:
            return 1, "Failed to get unit file state for poppy.service: No such file or directory"
        if "cat" in argv:
            return 0, "ExecStart=/usr/bin/poppy serve --profile ergo-jr --name ergo1 --announce"
        return (0, "active") if "is-active" in argv else (0, "enabled")

    def fetch(url: str) -> int | None:
        asked.append(url)
        return None

    probe.run, probe.fetch = user_unit, fetch
    monkeypatch.setattr(doctor_cmd, "system_probe", lambda: probe)
    result = doctor(port)
    assert asked == ["http://ergo1.local/"]
    checks = {c["name"]: c for c in result.json()["checks"]}
    assert checks["service"]["detail"] == "poppy.service active (systemctl --user)"
    assert failures(result) == {"page": [checks["page"]["fix"]]}
    assert checks["page"]["detail"] == "http://ergo1.local/: nothing answers"


def test_doctor_skips_the_service_and_page_when_not_installed(
    robot: Callable[..., tuple[VirtualBus, str]], monkeypatch: pytest.MonkeyPatch
) -> None:
    _, port = robot(set_up_robot())
    probe = doctor_cmd.system_probe()
    probe.run = lambda argv: (1, "Failed to get unit file state for poppy.service")
    monkeypatch.setattr(doctor_cmd, "system_probe", lambda: probe)
    result = doctor(port)
    assert result.code == 0
    checks = {c["name"]: c for c in result.json()["checks"]}
    assert checks["service"]["status"] == checks["page"]["status"] == "skip"
    assert checks["service"]["fix"] == "poppy service install --profile PROFILE"


# -- setup's refusals: one line saying what to do, exit 1, nothing written ---------------------


def setup_once(bus: VirtualBus, *places: int, options: tuple[str, ...] = ()) -> Result:
    """``poppy setup motors --motors m1`` on ``bus`` (its motors at ``places`` plugged first)."""
    for place in places:
        bus.attach(place)
    with serve_link(bus) as server:
        return run_poppy(
            "setup",
            "motors",
            "--profile",
            "ergo-jr",
            "--port",
            server.url,
            "--motors",
            "m1",
            *options,
            input="\n",
            env=ON_THE_LINK,
        )


def test_setup_says_when_nothing_answers() -> None:
    result = setup_once(kit())
    assert result.code == 1
    assert "nothing answers on emu://" in result.stderr
    assert "is m1 plugged and powered?" in result.stderr


def test_setup_says_to_unplug_all_but_one() -> None:
    bus = kit()
    result = setup_once(bus, 1, 2)
    assert result.code == 1
    assert "2 motors answer" in result.stderr and "unplug all but m1" in result.stderr
    assert [m.id for m in bus.motors] == [1] * 6


def test_setup_names_a_wrong_model() -> None:
    bus = kit("XL430-W250:1")
    result = setup_once(bus, 1)
    assert result.code == 1
    assert "found an XL430-W250 at ID 1 at 1000000 bps, protocol 2, m1 is an XL-320" in (
        result.stderr
    )


def test_setup_names_a_wrong_model_of_the_other_protocol() -> None:
    result = setup_once(build_bus_from_spec("MX-28:1", protocol=1))
    assert result.code == 1
    assert "found an MX-28 at ID 1 at 1000000 bps, protocol 1, m1 is an XL-320" in result.stderr


def test_setup_leaves_a_motor_already_right_as_it_is() -> None:
    bus = set_up_robot("XL-320:1")
    before = bytes(bus.motors[0].table.data)
    result = setup_once(bus, options=("--json",))
    assert result.code == 0, result.stderr
    assert result.json() == [
        {
            "motor": "m1",
            "found": {"id": 1, "baud": 1_000_000, "protocol": 2, "model": "XL-320"},
            "changes": {},
            "skipped": True,
            "next": None,
        }
    ]
    assert bytes(bus.motors[0].table.data) == before


def test_setup_stops_when_the_input_ends() -> None:
    bus = kit()
    with serve_link(bus) as server:
        result = run_poppy(
            "setup", "motors", "--profile", "ergo-jr", "--port", server.url, env=ON_THE_LINK
        )
    assert result.code == 1
    assert "input ended before m1 was set up" in result.stderr


def test_doctor_without_a_profile_takes_the_installed_service_s(
    robot: Callable[..., tuple[VirtualBus, str]], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    no_user_settings(tmp_path, monkeypatch)
    _, port = robot(set_up_robot())
    result = run_poppy("doctor", "--port", port, "--json")
    assert (result.code, result.json()["ok"]) == (0, True), result.stderr
    assert "checking ergo-jr, the profile poppy.service serves" in result.stderr


def test_doctor_without_a_profile_or_service_finds_the_robot_on_the_bus(
    robot: Callable[..., tuple[VirtualBus, str]],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    no_user_settings(tmp_path, monkeypatch)
    probe = replace(doctor_cmd.system_probe(), run=lambda argv: (1, ""))  # no service
    monkeypatch.setattr(doctor_cmd, "system_probe", lambda: probe)
    _, port = robot(set_up_robot())
    result = run_poppy("doctor", "--port", port, "--json")
    assert (result.code, result.json()["ok"]) == (0, True), result.stdout
    assert f"the motors on {port} are those of ergo-jr: checking it" in result.stderr
    _, other = robot(set_up_robot("XL-320:11-12"))
    result = run_poppy("doctor", "--port", other)
    assert result.code == 2 and "Traceback" not in result.stderr
    assert result.stderr.strip().splitlines()[-1] == (
        f"error: no profile given and the motors on {other} are no known robot's: "
        "pass --profile NAME (see `poppy config list`)"
    )
