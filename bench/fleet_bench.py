"""``python -m bench fleet``: 20 virtual Ergo Jrs on Zenoh against today's WebSocket stream.

1. **Fan-out**: 20 robots in ``PROCESSES`` processes (``bench.fleet_procs``), each publishing
   its state at 50 Hz; one subscriber in this process (a ``Fleet`` on every robot's endpoint, as
   ``poppy fleet status`` is) counts the messages of each robot and their age (the robot's read
   time in the message against this clock: one machine, one clock). A second, slow subscriber
   (20 ms per message) runs beside it. The same robots then stream over pypot's WebSocket at
   50 Hz to 20 clients (their frames carry no time: rate only). CPU per robot is the robot
   processes' CPU time over the window, divided by 20, against the same robots serving nothing.
2. **Sync loops under slow subscribers**: the robots' own sync loop rates (their health) with
   no subscriber, then with ``SLOW_SUBSCRIBERS`` Zenoh sessions that cannot keep up.
3. **Start spread** (``bench.fleet_spread``): ``fleet run`` and ``fleet play`` on the 20
   robots with a shared start time, over ``TRIALS`` commands each.
4. **Teleop goals at 100 Hz**: a follower served in this process gets 100 goals/s over Zenoh
   (its ``goals`` stream) and over the WebSocket (``{motor: {goal_position}}`` frames); the
   latency is from the send to the server's handling of that goal (matched by its value).
5. **Signed requests** (``bench.fleet_auth``): what signing and checking add per request (CPU
   time), and a request's round trip to a robot with a token against one without.
"""

from __future__ import annotations

import contextlib
import json
import os
import threading
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

from bench.fleet_auth import signed_requests
from bench.fleet_procs import (
    PROCESSES,
    ROBOTS,
    SLOW_S,
    SLOW_SUBSCRIBERS,
    cpu_per_robot,
    cpu_s,
    robot_processes,
    slow_subscribers,
)
from bench.fleet_report import build_result
from bench.fleet_router import RouterProcess
from bench.fleet_spread import play_spread
from bench.registry import BenchContext, BenchResult, register
from bench.side_by_side import percentile

RATE_HZ = 50.0
WINDOW_S = 5.0
WARMUP_S = 2.0
TELEOP_HZ = 100.0
TELEOP_S = 4.0


def fanout_zenoh(router: Any = None) -> dict[str, Any]:
    """The fan-out, peer to peer or (``router``: a ``bench.fleet_router.RouterProcess``)
    through a router, whose CPU is then measured over the same window."""
    from poppy_core.remote.zenoh_fleet import Fleet
    from poppy_core.zenoh_wire import ZenohSettings

    endpoint = router.endpoint if router is not None else None
    with robot_processes(zenoh=True, ws=False, router=endpoint) as (procs, robots):
        endpoints = list({r["endpoint"]: 0 for r in robots})
        settings = ZenohSettings(connect=tuple(endpoints))
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

        with slow_subscribers(1, endpoints), Fleet(settings) as fleet:
            fleet.on_state(state)
            fleet.on_health(health)
            time.sleep(WARMUP_S)
            measuring.set()
            router_before = cpu_s([router.proc]) if router is not None else 0.0
            cpu = cpu_per_robot(procs, WINDOW_S)
            router_after = cpu_s([router.proc]) if router is not None else 0.0
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
            "router_cpu_pct": (router_after - router_before) / WINDOW_S * 100.0
            if router is not None
            else None,
        }


def sync_underslow_subscribers() -> dict[str, Any]:
    """The robots' ``present`` sync loop rates (their health), without and then with
    ``SLOW_SUBSCRIBERS`` slow subscribers on every robot's state."""
    from poppy_core.remote.zenoh_fleet import Fleet
    from poppy_core.zenoh_wire import ZenohSettings

    with robot_processes(zenoh=True, ws=False) as (procs, robots):
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
                with slow_subscribers(count, endpoints) if count else contextlib.nullcontext():
                    time.sleep(WARMUP_S)
                    rates.clear()
                    cpu = cpu_per_robot(procs, WINDOW_S)
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

    with robot_processes(zenoh=False, ws=True) as (procs, robots):
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
        cpu = cpu_per_robot(procs, WINDOW_S)
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
    with robot_processes(zenoh=False, ws=False) as (procs, _):
        time.sleep(WARMUP_S)
        return cpu_per_robot(procs, WINDOW_S)


def teleop_goals() -> dict[str, Any]:
    from websockets.sync.client import connect

    from bench.procs import free_port
    from poppy_core import from_profile
    from poppy_core.assembly import Listen, ServeSpec, ZenohSettings, serve
    from poppy_core.assembly import ZenohSettings as Settings
    from poppy_core.remote.zenoh_fleet import Fleet
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


@register(
    "fleet", "20 Ergo Jrs on Zenoh: state fan-out vs WebSocket, fleet play spread, teleop, signing"
)
def fleet_bench(ctx: BenchContext) -> BenchResult:
    """Fan-out, start spread and teleop goals (one run each: the machine is shared)."""
    import tempfile

    raw: dict[str, Any] = {"robots": ROBOTS, "processes": PROCESSES, "window_s": WINDOW_S}
    raw["load_before"] = os.getloadavg()[0]
    raw["zenoh"] = fanout_zenoh()
    raw["slow"] = sync_underslow_subscribers()
    raw["ws"] = fanout_ws()
    raw["idle_cpu_per_robot_pct"] = idle_cpu()
    with tempfile.TemporaryDirectory() as tmp:
        raw["play"] = play_spread(Path(tmp))
    with RouterProcess() as router:
        raw["router"] = {"zenoh": fanout_zenoh(router)}
        with tempfile.TemporaryDirectory() as tmp:
            before, began = cpu_s([router.proc]), time.monotonic()
            raw["router"]["play"] = play_spread(Path(tmp), router.endpoint)
            raw["router"]["play_router_cpu_pct"] = (
                (cpu_s([router.proc]) - before) / (time.monotonic() - began) * 100.0
            )
    raw["teleop"] = teleop_goals()
    raw["encoding"] = encoding()
    raw["auth"] = signed_requests()
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
