"""``python -m bench fleet``: 20 virtual Ergo Jrs on Zenoh against today's WebSocket stream.

1. **Fan-out**: 20 robots in ``PROCESSES`` processes (``bench.fleet_robots``), each publishing
   its state at 50 Hz; one subscriber in this process (a ``Fleet`` on every robot's endpoint, as
   ``poppy fleet status`` is) counts the messages of each robot and their age (the robot's read
   time in the message against this clock: one machine, one clock). A second, slow subscriber
   (20 ms per message) runs beside it: the robots' sync loops must not notice. The same robots
   then stream over pypot's WebSocket at 50 Hz to 20 clients (their frames carry no time: rate
   only). CPU per robot is the robot processes' CPU time over the window, divided by 20,
   against the same robots serving nothing.
2. **fleet play spread**: ``Fleet.command`` starts a primitive on the 20 robots with a shared
   start time; each robot logs when it started it (``--starts``); the spread is the latest
   minus the earliest, over ``TRIALS`` commands.
3. **Teleop goals at 100 Hz**: a follower served in this process gets 100 goals/s over Zenoh
   (its ``goals`` stream) and over the WebSocket (``{motor: {goal_position}}`` frames); the
   latency is from the send to the server's handling of that goal (matched by its value).
"""

from __future__ import annotations

import contextlib
import json
import os
import subprocess
import sys
import threading
import time
from collections import defaultdict
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from bench.fleet_report import build_result
from bench.procs import interrupt
from bench.registry import POPPY_PYTHON, REPO_ROOT, BenchContext, BenchResult, register
from bench.side_by_side import percentile

ROBOTS = 20
PROCESSES = 4
RATE_HZ = 50.0
WINDOW_S = 5.0
WARMUP_S = 2.0
TRIALS = 50
"""Fleet play commands timed (after one warm-up): enough for a p90 and a max that mean something
(the goal is checked on the max, a bound over every trial)."""
TELEOP_HZ = 100.0
TELEOP_S = 4.0
SLOW_S = 0.02
SLOW_SUBSCRIBERS = 20
SLOW_SUBSCRIBER = """
import os, sys, time
from poppy_core.remote.zenoh_fleet import Fleet
from poppy_core.zenoh_wire import ZenohSettings
count, delay, endpoints = int(sys.argv[1]), float(sys.argv[2]), tuple(sys.argv[3:])
fleets = [Fleet(ZenohSettings(connect=endpoints)) for _ in range(count)]
for fleet in fleets:
    fleet.on_state(lambda name, state: time.sleep(delay))
print("ready", flush=True)
try:
    while True:
        time.sleep(1)
except KeyboardInterrupt:
    os._exit(0)  # a session sleeping in its callback would not close in time: the sockets go
"""
"""COUNT Zenoh sessions (each its own client, as COUNT `fleet status` would be), each on every
robot's state, each sleeping DELAY s per message: subscribers that cannot keep up."""
TICK = os.sysconf("SC_CLK_TCK")


@contextmanager
def _robots(
    zenoh: bool, ws: bool, starts: Path | None = None, env: dict[str, str] | None = None
) -> Iterator[tuple[list[Any], list[dict[str, Any]]]]:
    """Start the robot processes (``env``: more environment); yields them and one record per
    robot (name, endpoint, ws)."""
    procs, robots = [], []
    python = str(POPPY_PYTHON) if POPPY_PYTHON.exists() else sys.executable
    try:
        per = ROBOTS // PROCESSES
        for index in range(PROCESSES):
            args = [
                python,
                "-m",
                "bench.fleet_robots",
                "--count",
                str(per),
                "--first",
                str(index * per),
            ]
            args += ["--zenoh"] if zenoh else []
            args += ["--ws"] if ws else []
            args += ["--starts", str(starts)] if starts is not None else []
            full = {**os.environ, **(env or {}), "PYTHONPATH": str(REPO_ROOT)}
            procs.append(
                subprocess.Popen(args, cwd=REPO_ROOT, stdout=subprocess.PIPE, text=True, env=full)
            )
        for proc in procs:
            assert proc.stdout is not None
            for line in proc.stdout:
                if line.strip() == "ready":
                    break
                name, endpoint, ws_port = line.split()
                robots.append({"name": name, "endpoint": endpoint, "ws": int(ws_port)})
            else:
                raise RuntimeError("a robot process ended before it served")
        yield procs, robots
    finally:
        for proc in procs:
            interrupt(proc)
            if proc.stdout is not None:
                proc.stdout.close()


def _cpu_s(procs: list[Any]) -> float:
    total = 0
    for proc in procs:
        fields = Path(f"/proc/{proc.pid}/stat").read_text().rsplit(")", 1)[1].split()
        total += int(fields[11]) + int(fields[12])  # utime, stime
    return total / TICK


def _cpu_per_robot(procs: list[Any], window_s: float) -> float:
    before = _cpu_s(procs)
    time.sleep(window_s)
    return (_cpu_s(procs) - before) / window_s / ROBOTS * 100.0


def fanout_zenoh() -> dict[str, Any]:
    from poppy_core.remote.zenoh_fleet import Fleet
    from poppy_core.zenoh_wire import ZenohSettings

    with _robots(zenoh=True, ws=False) as (procs, robots):
        settings = ZenohSettings(connect=tuple(r["endpoint"] for r in robots))
        counts: dict[str, int] = defaultdict(int)
        ages: list[float] = []
        loops: dict[str, list[float]] = defaultdict(list)
        measuring = threading.Event()

        def state(name: str, message: Any) -> None:
            if measuring.is_set():
                counts[name] += 1
                ages.append(time.time() - message.stamp)

        def health(name: str, data: dict[str, Any]) -> None:
            if measuring.is_set():
                for bus in data.get("buses", {}).values():
                    hz = bus.get("loop_hz", {}).get("present")
                    if hz is not None:
                        loops[name].append(float(hz))

        with _slow_subscribers(1, [r["endpoint"] for r in robots]), Fleet(settings) as fleet:
            fleet.on_state(state)
            fleet.on_health(health)
            time.sleep(WARMUP_S)
            measuring.set()
            cpu = _cpu_per_robot(procs, WINDOW_S)
            measuring.clear()
        ages.sort()
        rates = sorted(counts.get(r["name"], 0) / WINDOW_S for r in robots)
        sync = sorted(hz for values in loops.values() for hz in values)
        return {
            "robots": len(robots),
            "rate_min_hz": rates[0],
            "rate_median_hz": rates[len(rates) // 2],
            "age_p50_ms": (percentile(ages, 0.5) or 0) * 1000,
            "age_p99_ms": (percentile(ages, 0.99) or 0) * 1000,
            "cpu_per_robot_pct": cpu,
            "sync_hz_min": sync[0] if sync else None,
            "sync_hz_median": sync[len(sync) // 2] if sync else None,
        }


@contextmanager
def _slow_subscribers(count: int, endpoints: list[str]) -> Iterator[None]:
    """``count`` slow subscribers (``SLOW_SUBSCRIBER``) in a process of their own."""
    slow = subprocess.Popen(
        [sys.executable, "-c", SLOW_SUBSCRIBER, str(count), str(SLOW_S), *endpoints],
        cwd=REPO_ROOT,
        stdout=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONPATH": str(REPO_ROOT)},
    )
    try:
        assert slow.stdout is not None
        if slow.stdout.readline().strip() != "ready":
            raise RuntimeError("the slow subscribers did not start")
        yield
    finally:
        interrupt(slow)
        if slow.stdout is not None:
            slow.stdout.close()


def sync_under_slow_subscribers() -> dict[str, Any]:
    """The robots' ``present`` sync loop rates (their health), without and then with
    ``SLOW_SUBSCRIBERS`` slow subscribers on every robot's state."""
    from poppy_core.remote.zenoh_fleet import Fleet
    from poppy_core.zenoh_wire import ZenohSettings

    with _robots(zenoh=True, ws=False) as (procs, robots):
        endpoints = [r["endpoint"] for r in robots]
        rates: list[float] = []

        def health(name: str, data: dict[str, Any]) -> None:
            for bus in data.get("buses", {}).values():
                hz = bus.get("loop_hz", {}).get("present")
                if hz is not None:
                    rates.append(float(hz))

        found: dict[str, Any] = {}
        with Fleet(ZenohSettings(connect=tuple(endpoints))) as fleet:
            fleet.on_health(health)
            for label, count in (("none", 0), ("slow", SLOW_SUBSCRIBERS)):
                with _slow_subscribers(count, endpoints) if count else contextlib.nullcontext():
                    time.sleep(WARMUP_S)
                    rates.clear()
                    cpu = _cpu_per_robot(procs, WINDOW_S)
                    seen = sorted(rates)
                found[label] = {
                    "subscribers": count,
                    "sync_hz_min": seen[0] if seen else None,
                    "sync_hz_median": seen[len(seen) // 2] if seen else None,
                    "samples": len(seen),
                    "cpu_per_robot_pct": cpu,
                }
    return found


def fanout_ws() -> dict[str, Any]:
    from websockets.sync.client import connect

    with _robots(zenoh=False, ws=True) as (procs, robots):
        counts: dict[str, int] = defaultdict(int)
        measuring = threading.Event()
        stop = threading.Event()

        def client(robot: dict[str, Any]) -> None:
            with connect(f"ws://127.0.0.1:{robot['ws']}/?rate_hz={RATE_HZ:g}") as ws:
                while not stop.is_set():
                    try:
                        ws.recv(timeout=0.5)
                    except TimeoutError:
                        continue
                    if measuring.is_set():
                        counts[robot["name"]] += 1

        threads = [threading.Thread(target=client, args=(r,), daemon=True) for r in robots]
        for thread in threads:
            thread.start()
        time.sleep(WARMUP_S)
        measuring.set()
        cpu = _cpu_per_robot(procs, WINDOW_S)
        measuring.clear()
        stop.set()
        for thread in threads:
            thread.join(2.0)
        rates = sorted(counts.get(r["name"], 0) / WINDOW_S for r in robots)
        return {
            "robots": len(robots),
            "rate_min_hz": rates[0],
            "rate_median_hz": rates[len(rates) // 2],
            "cpu_per_robot_pct": cpu,
        }


def idle_cpu() -> float:
    with _robots(zenoh=False, ws=False) as (procs, _):
        time.sleep(WARMUP_S)
        return _cpu_per_robot(procs, WINDOW_S)


STARTS = {
    "run": ("/api/v1/primitives/sinus/start", None, "/api/v1/primitives/sinus/stop"),
    "play": ("/api/v1/moves/wave/play", {"speed": 1.0}, "/api/v1/moves/wave/stop"),
}
"""What each start measures: ``fleet run sinus`` and ``fleet play wave`` (start, body, stop)."""


def _wave(moves: Path) -> dict[str, str]:
    """Save the move ``fleet play`` plays in ``moves`` (1 s of ``m1`` from its rest pose and
    back); the robots' environment that makes it their library."""
    from poppy_core.motion.move import Move
    from poppy_core.motion.move_library import MOVES_DIR_ENV, save_move

    moves.mkdir(parents=True, exist_ok=True)
    frames = [{"m1": 10.0 * (1 - abs(1 - i / 25))} for i in range(51)]
    save_move(Move.from_frames(50.0, frames), moves / "wave.move")
    return {MOVES_DIR_ENV: str(moves)}


def play_spread(tmp: Path) -> dict[str, Any]:
    from poppy_core.remote.zenoh_fleet import Fleet
    from poppy_core.zenoh_wire import ZenohSettings

    starts = tmp / "starts.txt"
    env = _wave(tmp / "moves")
    found: dict[str, Any] = {}
    with _robots(zenoh=True, ws=False, starts=starts, env=env) as (_, robots):
        names = [r["name"] for r in robots]
        settings = ZenohSettings(connect=tuple(r["endpoint"] for r in robots))
        with Fleet(settings, timeout_s=5.0) as fleet:
            fleet.wait_for(names, 10.0)
            for what, (path, body, stop) in STARTS.items():
                found[what] = _spread(fleet, names, starts, path, body, stop)
    return found


def _spread(
    fleet: Any, names: list[str], starts: Path, path: str, body: Any, stop: str
) -> dict[str, Any]:
    """``TRIALS`` starts of ``path`` on every robot together (after a first one kept apart)."""
    spreads, offsets, within = [], [], []
    first: dict[str, float] = {}
    for trial in range(TRIALS + 1):
        starts.write_text("")
        outcomes = fleet.command(names, "POST", path, body)
        assert all(o.ok for o in outcomes), [o.message for o in outcomes if not o.ok]
        stamps = _stamps(starts, len(names))
        times = [t for _, t in stamps]
        late = [t - (fleet.last_start_at or 0) for t in times]
        if trial == 0:
            first = {
                "spread_ms": (max(times) - min(times)) * 1000,
                "late_max_ms": max(late) * 1000,
            }
        else:
            spreads.append(max(times) - min(times))
            offsets.extend(late)
            within.append(_within_process(stamps))
        fleet.command(names, "POST", stop, together=False)
    spreads.sort()
    offsets.sort()
    within.sort()
    return {
        "trials": len(spreads),
        "spread_p50_ms": (percentile(spreads, 0.5) or 0) * 1000,
        "spread_p90_ms": (percentile(spreads, 0.9) or 0) * 1000,
        "spread_p99_ms": (percentile(spreads, 0.99) or 0) * 1000,
        "spread_max_ms": spreads[-1] * 1000,
        "late_p50_ms": (percentile(offsets, 0.5) or 0) * 1000,
        "late_p99_ms": (percentile(offsets, 0.99) or 0) * 1000,
        "late_min_ms": offsets[0] * 1000,
        "within_p50_ms": (percentile(within, 0.5) or 0) * 1000,
        "within_max_ms": within[-1] * 1000,
        "first": first,
    }


def _stamps(path: Path, count: int, timeout_s: float = 5.0) -> list[tuple[str, float]]:
    """The ``count`` (process, start time) the robots logged (a robot's primitive begins in its
    own thread, maybe just after the command's reply)."""
    deadline = time.monotonic() + timeout_s
    while True:
        lines = path.read_text().splitlines()
        if len(lines) >= count or time.monotonic() > deadline:
            return [(line.split()[0], float(line.split()[1])) for line in lines]
        time.sleep(0.01)


def _within_process(stamps: list[tuple[str, float]]) -> float:
    """The largest spread of the starts of the robots served by one process."""
    by_process: dict[str, list[float]] = defaultdict(list)
    for pid, stamp in stamps:
        by_process[pid].append(stamp)
    return max(max(times) - min(times) for times in by_process.values())


def teleop_goals() -> dict[str, Any]:
    from websockets.sync.client import connect

    from bench.procs import free_port
    from poppy_core.assembly import Listen, ServeSpec, ZenohSettings, serve
    from poppy_core.assembly import ZenohSettings as Settings
    from poppy_core.remote.zenoh_fleet import Fleet
    from poppy_core.robot import from_profile
    from poppy_core.server.service import RobotService

    endpoint = f"tcp/127.0.0.1:{free_port()}"
    arrived: dict[float, float] = {}
    out: dict[str, Any] = {}
    with from_profile("ergo-jr", sim=True) as robot:
        robot.compliant = False
        spec = ServeSpec(
            ws=Listen(port=0), zenoh=ZenohSettings(listen=(endpoint,)), name="follower"
        )
        servers = serve(robot, spec)
        try:
            node = servers.zenoh
            assert node is not None and servers.ws is not None
            real_apply = node.apply_goals

            def apply(payload: bytes) -> dict[str, float]:
                arrived[json.loads(payload)["goals"]["m1"]] = time.perf_counter()
                return real_apply(payload)

            node.apply_goals = apply  # type: ignore[method-assign]
            real_write = RobotService.write_many

            def write_many(self: RobotService, commands: Any) -> Any:
                arrived[commands["m1"]["goal_position"]] = time.perf_counter()
                return real_write(self, commands)

            RobotService.write_many = write_many  # type: ignore[method-assign]
            with Fleet(Settings(connect=(endpoint,))) as fleet:
                fleet.wait_for(["follower"])
                send = fleet.goals("follower")
                _paced(lambda value: send({"m1": value}), arrived, 0.0, warm_up=True)
                out["zenoh"] = _paced(lambda value: send({"m1": value}), arrived, 0.0)
            with connect(f"ws://127.0.0.1:{servers.ws.port}/") as ws:
                _paced(
                    lambda value: ws.send(json.dumps({"m1": {"goal_position": value}})),
                    arrived,
                    50.0,
                    warm_up=True,
                )
                out["ws"] = _paced(
                    lambda value: ws.send(json.dumps({"m1": {"goal_position": value}})),
                    arrived,
                    50.0,
                )
            RobotService.write_many = real_write  # type: ignore[method-assign]
        finally:
            servers.stop()
    return out


def _paced(
    send: Any, arrived: dict[float, float], base: float, *, warm_up: bool = False
) -> dict[str, Any]:
    """Send goals at ``TELEOP_HZ``; their latency to the server (``warm_up``: 0.5 s, for the
    routes and connections to settle, with other values)."""
    sent: dict[float, float] = {}
    period = 1.0 / TELEOP_HZ
    next_at = time.perf_counter()
    count = int((0.5 if warm_up else TELEOP_S) * TELEOP_HZ)
    base += 25.0 if warm_up else 0.0
    for index in range(count):
        value = round(base + (index % 400) * 0.05 + index * 1e-6, 6)
        sent[value] = time.perf_counter()
        send(value)
        next_at += period
        time.sleep(max(0.0, next_at - time.perf_counter()))
    time.sleep(0.3)
    latencies = sorted(arrived[v] - t for v, t in sent.items() if v in arrived)
    return {
        "sent": count,
        "handled": len(latencies),
        "p50_ms": (percentile(latencies, 0.5) or 0) * 1000,
        "p99_ms": (percentile(latencies, 0.99) or 0) * 1000,
    }


def encoding() -> dict[str, Any]:
    """Bytes and microseconds of one Ergo Jr state message: packed (chosen) against JSON."""
    import timeit

    from poppy_core.zenoh_wire import pack_state, state_json, unpack_state

    motors = {
        f"m{i}": {
            "present_position": 12.345 + i,
            "present_speed": -3.25,
            "present_load": 4.5,
            "present_temperature": 35.0,
            "compliant": False,
            "online": True,
        }
        for i in range(1, 7)
    }
    packed, text = pack_state(1, time.time(), motors), state_json(1, time.time(), motors)
    n = 20000

    def best(func: Any) -> float:
        return min(timeit.repeat(func, number=n, repeat=5)) / n * 1e6

    return {
        "packed": {
            "bytes": len(packed),
            "encode_us": best(lambda: pack_state(1, 0.0, motors)),
            "decode_us": best(lambda: unpack_state(packed)),
        },
        "json": {
            "bytes": len(text),
            "encode_us": best(lambda: state_json(1, 0.0, motors)),
            "decode_us": best(lambda: json.loads(text)),
        },
    }


@register("fleet", "20 Ergo Jrs on Zenoh: state fan-out vs WebSocket, fleet play spread, teleop")
def fleet_bench(ctx: BenchContext) -> BenchResult:
    """Fan-out, start spread and teleop goals (one run each: the machine is shared)."""
    import tempfile

    raw: dict[str, Any] = {"robots": ROBOTS, "processes": PROCESSES, "window_s": WINDOW_S}
    raw["load_before"] = os.getloadavg()[0]
    raw["zenoh"] = fanout_zenoh()
    raw["slow"] = sync_under_slow_subscribers()
    raw["ws"] = fanout_ws()
    raw["idle_cpu_per_robot_pct"] = idle_cpu()
    with tempfile.TemporaryDirectory() as tmp:
        raw["play"] = play_spread(Path(tmp))
    raw["teleop"] = teleop_goals()
    raw["encoding"] = encoding()
    raw["load_after"] = os.getloadavg()[0]
    settings = {
        "ROBOTS": ROBOTS,
        "PROCESSES": PROCESSES,
        "WINDOW_S": WINDOW_S,
        "WARMUP_S": WARMUP_S,
        "SLOW_S": SLOW_S,
        "SLOW_SUBSCRIBERS": SLOW_SUBSCRIBERS,
        "TELEOP_HZ": TELEOP_HZ,
    }
    return build_result(raw, settings)
