"""The durations the tests no longer assert, measured one run at a time (``timing_bench``).

Each probe builds what its test builds (a simulated Ergo Jr, a served one, a virtual bus, the
TUI) and returns the quantity the test used to bound: seconds, or periods for the grid phase.
"""

from __future__ import annotations

import asyncio
import importlib
import statistics
import tempfile
import threading
import time
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from pathlib import Path

import httpx
import numpy as np

from poppy_core import from_profile
from poppy_core.bus import DxlBus, PortInfo, scan
from poppy_core.emulator import (
    FaultInjector,
    VirtualBus,
    VirtualMotor,
    build_bus_from_spec,
    serve_link,
    serve_pty,
)
from poppy_core.models import model_by_name
from poppy_core.motion import Move, MovePlayer, PositionWatcher, read_move
from poppy_core.motion.teleop.session import teleoperate
from poppy_core.protocol import ping
from poppy_core.robot import Robot
from poppy_core.schedule import Gate
from poppy_core.server import ServerThread, create_app

GETS = 40  # test_concurrency_stream: 40 GETs from 8 threads during a 1.5 s waiting goto
GOTO_S = 1.5
LATE_S = 0.015  # test_on_time_adapter: motor 9's ping answered 15 ms late, once
GRID_HZ = 4.0  # test_shared_start: two 4 Hz loops opened 1.5 periods apart
TELEOP_S = 1.5  # test_teleoperate: a 1.5 s teleoperation recorded at 50 Hz

scan_module = importlib.import_module("poppy_core.bus.scan")  # the package's `scan` is the function


@contextmanager
def ergo() -> Iterator[Robot]:
    """A simulated Ergo Jr (ideal servos, in-process link), stiff at 0°."""
    with from_profile("ergo-jr", sim=True, sensors=False) as robot:
        robot.compliant = False
        robot.goto_position({m.name: 0.0 for m in robot.motors}, 0.3, wait=True)
        yield robot


def gets_during_goto() -> tuple[float, float]:
    """(the 40 GETs' time, the waiting goto's answer time) on a served Ergo Jr."""
    robot = from_profile("ergo-jr", sim=True, sensors=False)
    server = ServerThread(create_app(robot)).start()
    try:
        robot.m1.compliant = False
        answered: list[float] = []

        def slow_goto() -> None:
            with httpx.Client(base_url=server.url, timeout=30.0) as http:
                t0 = time.monotonic()
                body = {"position": 30, "duration": GOTO_S, "wait": True}
                http.post("/motors/m1/goto.json", json=body).raise_for_status()
                answered.append(time.monotonic() - t0)

        mover = threading.Thread(target=slow_goto)
        mover.start()
        time.sleep(0.2)
        with httpx.Client(base_url=server.url, timeout=30.0) as client:
            url = "/motors/m1/registers/present_position/value.json"
            t0 = time.monotonic()
            with ThreadPoolExecutor(8) as pool:
                list(pool.map(lambda _: client.get(url).raise_for_status(), range(GETS)))
            all_done = time.monotonic() - t0
        mover.join()
        return all_done, answered[0]
    finally:
        server.stop()
        robot.close()


def goto_end_s(robot: Robot) -> float:
    """How long a 1 s minimum-jerk goto takes to report done."""
    robot.goto_position({"m1": 0.0}, 0.3, wait=True)
    start = time.monotonic()
    handle = robot.goto_position({"m1": 60, "m2": -30}, 1.0)
    handle.wait()
    return time.monotonic() - start


def ramp_move(seconds: float, rate: float = 50.0) -> Move:
    """m2 from 0° to 40° and m4 from 0° to -20° in ``seconds``."""
    t = np.arange(int(seconds * rate) + 1) / rate
    return Move(rate, ["m2", "m4"], np.column_stack([40 * t / seconds, -20 * t / seconds]))


def played_s(robot: Robot, *, speed: float = 1.0, loops: int = 1, backwards: bool = False) -> float:
    """``played_s`` of the 1 s ramp played so (test_move_play, test_record_play_cmd)."""
    player = MovePlayer(robot, ramp_move(1.0), speed=speed, loops=loops, backwards=backwards)
    return player.play().played_s


def stopped_after_s(robot: Robot, stop_at_s: float = 0.4) -> float:
    """``played_s`` of a 5 s move stopped ``stop_at_s`` after its start (test_move_play)."""
    player = MovePlayer(robot, ramp_move(5.0), ramp_s=0.1)
    player.start()
    threading.Timer(stop_at_s, player.stop).start()
    player.wait()
    return player.played_s


class _Stamped(PositionWatcher):
    def __init__(self, robot: Robot) -> None:
        super().__init__(robot, GRID_HZ, "m1")
        self.updated: list[float] = []

    def update(self) -> None:
        self.updated.append(time.monotonic())
        super().update()


def grid_phase(robot: Robot) -> float:
    """The median distance of the updates to the shared grid, in periods (0 to 0.5)."""
    period = 1.0 / GRID_HZ
    at = time.monotonic()
    watchers = [_Stamped(robot) for _ in range(2)]
    gates = [Gate(at=at), Gate(at=at)]
    for watcher, gate in zip(watchers, gates, strict=True):
        watcher.start(gate=gate)
    gates[0].open()
    time.sleep(max(0.0, at + 1.5 * period - time.monotonic()))
    gates[1].open()
    while not all(len(w.updated) >= 6 for w in watchers):
        time.sleep(0.01)
    for watcher in watchers:
        watcher.stop()
    phases = []
    for watcher in watchers:
        for t in watcher.updated[1:]:
            cycles = ((t - at) / period) % 1.0
            phases.append(min(cycles, 1.0 - cycles))
    return statistics.median(phases)


def teleop_record_s() -> float:
    """The recorded move's duration of a 1.5 s teleoperation at 50 Hz."""
    with (
        from_profile("ergo-jr", sim=True, sensors=False) as leader,
        from_profile("ergo-jr", sim=True, sensors=False) as follower,
        tempfile.TemporaryDirectory() as folder,
    ):
        path = Path(folder) / "teleop.move"
        teleoperate(leader, follower, "m1=m1", rate_hz=50, duration_s=TELEOP_S, record=path).run()
        return read_move(path).duration_s


def key_latency_s() -> float:
    """The slowest of six tab switches while the TUI scans a 25-motor bus."""
    from poppy_cli.tui.app import make_app

    def no_ports() -> list[PortInfo]:
        return []

    async def run(url: str) -> float:
        app = make_app(url, port_lister=no_ports, live_period_s=0)
        async with app.run_test(size=(100, 40)) as pilot:
            screen = app.main
            await pilot.pause(0.2)
            delays = []
            for i in range(6):
                start = time.monotonic()
                await pilot.press(("f3", "f1", "f2")[i % 3])
                delays.append(screen.tab_switched_s - start)
            screen.action_abort()
            return max(delays)

    server = serve_link(build_bus_from_spec("MX-28:1-25", protocol=1, baudrate=1_000_000))
    try:
        return asyncio.run(run(server.url))
    finally:
        server.stop()


class _LateOnce(FaultInjector):
    """Holds the reply numbered ``which`` (1 = the first) back ``delay_s`` more."""

    def __init__(self, which: int, delay_s: float) -> None:
        super().__init__()
        self.which, self.delay_s, self.count = which, delay_s, 0

    def filter_reply(self, data: bytes) -> bytes | None:
        self.count += 1
        self._extra_delay_s = self.delay_s if self.count == self.which else 0.0
        return data


def doubted_latency_s() -> tuple[float, float]:
    """(latency learned from a reply 15 ms late, latency kept after the doubt) in a scan."""
    doubted: list[tuple[float, float]] = []
    real_doubt = scan_module.doubt_learned

    def doubt_learned(bus: DxlBus, before_s: float, motor_id: int) -> None:
        learned = bus.latency_s
        real_doubt(bus, before_s, motor_id)
        doubted.append((learned, bus.latency_s))

    motors = [VirtualMotor(model_by_name("MX-28"), i, 1_000_000) for i in (3, 9)]
    virtual = VirtualBus(motors, 1, wire_timing=True, latency_s=0.001, faults=_LateOnce(3, LATE_S))
    scan_module.doubt_learned = doubt_learned  # type: ignore[assignment]
    try:
        with serve_link(virtual) as server:
            scan(server.url, [1_000_000], [1], ids=range(30), latency_s=0.001)
    finally:
        scan_module.doubt_learned = real_doubt  # type: ignore[assignment]
    return doubted[0] if doubted else (float("nan"), float("nan"))


class _Garble(FaultInjector):
    def filter_reply(self, data: bytes) -> bytes | None:
        garbled = bytearray(data)
        garbled[len(data) // 2] ^= 0x10
        return bytes(garbled)


def garbled_exchange_s() -> float:
    """How long an exchange whose only reply is garbled takes (its deadline: an hour)."""
    virtual = build_bus_from_spec("XL-320:1", protocol=2, faults=_Garble())
    with serve_pty(virtual) as server, DxlBus(server.url, protocol=2, timeout_s=3600.0) as bus:
        start = time.monotonic()
        bus.exchange(ping(1), [(1, 3)])
        return time.monotonic() - start
