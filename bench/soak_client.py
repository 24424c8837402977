"""Run a poppy robot under faults until told to stop; print what it saw as one JSON line.

Run as ``python -m bench.soak_client --config FILE --port CONTROLLER=PATH [...]``, by
``bench.soak_bench``: it builds the robot from the pypot JSON config (ports replaced), stiffens
it, starts a ``Sinus`` primitive on every motor (50 Hz goals) and prints ``ready T`` (T on the
system-wide monotonic clock, shared with the process that injects the faults). Until a line
``stop`` arrives on stdin it records, from outside the library:

* each present-register read of each bus (``DxlBus.sync_read`` wrapped on the instance) and
  each update of each motor's present position (its ``MotorLink.update`` wrapped), counted per
  second;
* every change of each motor's ``online`` flag and each bus's ``connected`` flag (polled every
  ``POLL_S``);
* once a second, for every motor online for the last ``CHECK_QUIET_S``: its goal position read
  back from the servo (under the bus lock) against the last goal the sync loop wrote to it;
* RSS and thread counts at ready and at stop, whether every thread is still alive, and how long
  ``robot.close()`` takes.
"""

from __future__ import annotations

import argparse
import json
import sys
import threading
import time
from collections import defaultdict
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from bench.peers._common import parse_controller_port, proc_status

POLL_S = 0.002
SETUP_ATTEMPTS = 3
CHECK_PERIOD_S = 1.0
CHECK_QUIET_S = 1.0
SINUS_AMPLITUDE_DEG = 10.0
SINUS_HZ = 0.5


class Bins:
    """Counts per whole second since ``t0`` (thread-safe enough: one writer per bin list)."""

    def __init__(self) -> None:
        self.t0: float | None = None
        self.counts: dict[str, list[int]] = defaultdict(list)

    def tick(self, key: str, now: float) -> None:
        if self.t0 is None or now < self.t0:
            return
        second = int(now - self.t0)
        bins = self.counts[key]
        while len(bins) <= second:
            bins.append(0)
        bins[second] += 1


class Recorder:
    """Wraps the robot's buses and motors, and watches flags (see the module doc)."""

    def __init__(self, robot: Any, config: Any) -> None:
        self.robot = robot
        self.config = config
        self.reads = Bins()
        self.updates = Bins()
        self.transitions: list[tuple[float, str, bool]] = []
        self.bus_transitions: list[tuple[float, str, bool]] = []
        self.written: dict[tuple[str, int], tuple[int, float]] = {}  # (bus, id) -> (raw, when)
        self.checked = 0
        self.lost: list[dict[str, Any]] = []
        self.unchecked = 0
        self.misread = 0
        self._stop = threading.Event()
        self._online_since: dict[str, float] = {}
        self._threads: list[threading.Thread] = []
        for name, bus in robot.buses.items():
            motors = [robot.motor(m) for m in config.motors_of_controller(name)]
            present = motors[0].model.register("present_position").address
            goal = motors[0].model.register("goal_position")
            bus.sync_read = self._wrap_read(name, present, bus.sync_read)  # type: ignore[method-assign]
            bus.sync_write = self._wrap_write(name, bus, goal, bus.sync_write)  # type: ignore[method-assign]
        from poppy_core.robot.motor_link import link_of

        for motor in robot.motors:
            link = link_of(motor)
            link.update = self._wrap_update(motor.name, link.update)  # type: ignore[method-assign]

    def _wrap_read(self, bus: str, address: int, read: Callable[..., Any]) -> Callable[..., Any]:
        def timed(at: int, length: int, ids: Sequence[int]) -> Any:
            if at == address:
                self.reads.tick(bus, time.monotonic())
            return read(at, length, ids)

        return timed

    def _wrap_write(
        self, name: str, bus: Any, goal: Any, write: Callable[..., Any]
    ) -> Callable[..., Any]:
        def recorded(at: int, data: Mapping[int, bytes]) -> Any:
            with bus.lock:  # the write and its record, as one step for the checker
                result = write(at, data)
                if at == goal.address:
                    now = time.monotonic()
                    for motor_id, raw in data.items():
                        self.written[(name, motor_id)] = (goal.decode(raw), now)
            return result

        return recorded

    def _wrap_update(self, name: str, update: Callable[..., Any]) -> Callable[..., Any]:
        def counted(values: Mapping[str, object]) -> Any:
            if "present_position" in values:
                self.updates.tick(name, time.monotonic())
            return update(values)

        return counted

    def start(self, t0: float) -> None:
        self.reads.t0 = self.updates.t0 = t0
        for target in (self._watch, self._check):
            thread = threading.Thread(target=target, name=target.__name__, daemon=True)
            thread.start()
            self._threads.append(thread)

    def stop(self) -> None:
        self._stop.set()
        for thread in self._threads:
            thread.join(5.0)

    def _watch(self) -> None:
        online = {m.name: m.online for m in self.robot.motors}
        connected = {name: True for name in self.robot.buses}
        now = time.monotonic()
        self._online_since = {name: now for name, up in online.items() if up}
        while not self._stop.wait(POLL_S):
            now = time.monotonic()
            for motor in self.robot.motors:
                if motor.online != online[motor.name]:
                    online[motor.name] = motor.online
                    self.transitions.append((now, motor.name, motor.online))
                    if motor.online:
                        self._online_since[motor.name] = now
                    else:
                        self._online_since.pop(motor.name, None)
            for name, health in self.robot.health().items():
                if health.connected != connected[name]:
                    connected[name] = health.connected
                    self.bus_transitions.append((now, name, health.connected))

    def _check(self) -> None:
        """Compare each quiet online motor's goal register with the last goal written to it."""
        while not self._stop.wait(CHECK_PERIOD_S):
            for name, bus in self.robot.buses.items():
                for motor_name in self.config.motors_of_controller(name):
                    self._check_one(name, bus, self.robot.motor(motor_name))

    def _check_one(self, bus_name: str, bus: Any, motor: Any) -> None:
        from poppy_core.errors import PoppyError

        since = self._online_since.get(motor.name)
        now = time.monotonic()
        if since is None or now - since < CHECK_QUIET_S or not motor.online:
            return
        register = motor.model.register("goal_position")
        with bus.lock:
            entry = self.written.get((bus_name, motor.id))
            if entry is None or entry[1] < since:
                return
            try:
                raw = register.decode(bus.read(motor.id, register.address, register.size))
                if raw != entry[0]:
                    # Protocol 1's 8-bit checksum lets some garbled replies through: a goal
                    # really lost reads the same wrong value twice more.
                    again = [
                        register.decode(bus.read(motor.id, register.address, register.size))
                        for _ in range(2)
                    ]
                    if entry[0] in again:
                        self.misread += 1
                        raw = entry[0]
                    else:
                        raw = again[0]
            except PoppyError:
                self.unchecked += 1
                return
        self.checked += 1
        if raw != entry[0] and motor.online and self._online_since.get(motor.name) == since:
            self.lost.append(
                {"t": now, "motor": motor.name, "written": entry[0], "read": raw, "at": entry[1]}
            )


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Build the robot, report ready, record until ``stop``, close; the JSON-ready record."""
    import poppy_core
    from poppy_core import from_config
    from poppy_core.errors import PoppyError
    from poppy_core.motion.builtins import Sinus
    from poppy_core.robot import RobotConfig, load_config

    record: dict[str, Any] = {"peer": "poppy", "error": None, "version": poppy_core.__version__}
    config = load_config(args.config)
    data = config.to_dict()
    for name, port in args.port:
        data["controllers"][name]["port"] = port
    config = RobotConfig.from_dict(data, source=args.config)
    start = time.perf_counter()
    for attempt in range(1, SETUP_ATTEMPTS + 1):  # a loaded machine may delay a first reply
        try:
            robot = from_config(config, fix_return_delay=True, start_sync=False, sensors=False)
            break
        except PoppyError as exc:
            if attempt == SETUP_ATTEMPTS:
                record["error"] = f"from_config failed: {type(exc).__name__}: {exc}"
                return record
    record["setup_s"] = time.perf_counter() - start
    record["setup_attempts"] = attempt
    recorder = Recorder(robot, config)
    closed = False
    try:
        robot.start_sync()
        robot.compliant = False
        sinus = Sinus(robot, 50.0, None, SINUS_AMPLITUDE_DEG, SINUS_HZ)
        sinus.start()
        time.sleep(args.warmup_s)
        t0 = time.monotonic()
        recorder.start(t0)
        record["start"] = proc_status()
        record["start"]["python_threads"] = threading.active_count()
        sys.stdout.write(f"ready {t0:.6f}\n")
        sys.stdout.flush()
        for line in sys.stdin:
            if line.strip() == "stop":
                break
        t_stop = time.monotonic()
        record["end"] = proc_status()
        record["end"]["python_threads"] = threading.active_count()
        recorder.stop()
        health = robot.health()
        record["alive"] = {
            "sync": {name: h.running for name, h in health.items()},
            "primitive": sinus.is_alive(),
        }
        record["health_end"] = {name: h.as_dict() for name, h in health.items()}
        began = time.perf_counter()
        robot.close()
        closed = True
        record["close_s"] = time.perf_counter() - began
        record["t0"] = t0
        record["duration_s"] = t_stop - t0
        record["reads_per_s"] = dict(recorder.reads.counts)
        record["updates_per_s"] = dict(recorder.updates.counts)
        record["transitions"] = [(round(t - t0, 4), n, up) for t, n, up in recorder.transitions]
        record["bus_transitions"] = [
            (round(t - t0, 4), n, up) for t, n, up in recorder.bus_transitions
        ]
        record["motors"] = {
            m.name: {
                "id": m.id,
                "bus": next(
                    c for c in config.controllers if m.name in config.motors_of_controller(c)
                ),
            }
            for m in robot.motors
        }
        record["goal_checks"] = {
            "checked": recorder.checked,
            "unchecked": recorder.unchecked,
            "misread": recorder.misread,
            "lost": len(recorder.lost),
            "examples": [{**x, "t": round(x["t"] - t0, 3)} for x in recorder.lost[:5]],
        }
    finally:
        if not closed:
            robot.close()
    return record


def main(argv: list[str] | None = None) -> int:
    """Parse the command line, run, print the JSON line; 0 on success, 1 on error."""
    parser = argparse.ArgumentParser(description="poppy robot under faults (soak client)")
    parser.add_argument("--config", required=True, help="pypot JSON config")
    parser.add_argument("--port", type=parse_controller_port, action="append", required=True)
    parser.add_argument("--warmup-s", type=float, default=2.0)
    record = run(parser.parse_args(argv))
    sys.stdout.write(json.dumps(record, sort_keys=True) + "\n")
    return 0 if record["error"] is None else 1


if __name__ == "__main__":
    sys.exit(main())
