"""The teleoperation benchmark's runs: emulators and probes here, the client in a subprocess.

One run: the leader's and the follower's buses are ``VirtualBus`` objects served on ptys by this
process (wire timing, 1 ms adapter latency), each wrapped in a ``BusProbe``; the client (poppy's
``bench.teleop_client`` or pypot's ``peers/pypot_arms_copy.py``) drives them from its own
process. Once it says ``STATE following``, the hand makes its strokes (tracking error sampled)
and its steps (latency), then, for a remote follower, the link is stalled for ``STALL_S`` while
the hand keeps moving. The client is stopped with SIGINT and prints its JSON line.
"""

from __future__ import annotations

import itertools
import json
import logging
import os
import resource
import signal
import subprocess
import threading
import time
import urllib.request
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from bench.link_proxy import LinkProxy
from bench.procs import interrupt
from bench.registry import POPPY_CLI, REPO_ROOT
from bench.teleop_probe import BusProbe, FollowerOf, Hand, Tracker, latencies
from poppy_core.emulator import VirtualBus, serve_pty
from poppy_core.models import model_by_name
from poppy_core.motion.teleop.joint_map import JointMap
from poppy_core.robot import Motor, RobotConfig
from poppy_core.robot.factory import virtual_buses

logger = logging.getLogger(__name__)

LATENCY_S = 0.001
STROKES_S = 8.0
STEPS = 30
STALL_S = 2.0
START_TIMEOUT_S = 60.0
HAND_SPAN_DEG = 70.0
"""The hand moves each joint within ±70° of the middle of its usable range."""
MARGIN_DEG = 10.0


@dataclass(frozen=True)
class Durations:
    """How long each phase lasts (shorter for development runs)."""

    strokes_s: float = STROKES_S
    steps: int = STEPS
    stall_s: float = STALL_S


def _motor(config: RobotConfig, name: str) -> Motor:
    return Motor.from_config(name, config.motors[name], model_by_name(config.motors[name].type))


def pairing(
    leader: RobotConfig, follower: RobotConfig, mapping: JointMap
) -> tuple[dict[str, tuple[float, float]], FollowerOf, dict[str, int]]:
    """The hand's motor-frame range per leader joint, the expected follower goal of each, and
    the leader's servo ids.

    The ranges keep the mapped targets inside both robots' limits, read both ways: poppy's (a
    config's ``angle_limit`` is in the user frame, converted for the servo) and pypot's (written
    to the servo unchanged, i.e. in the motor frame), so that both libraries can follow.
    """
    ranges: dict[str, tuple[float, float]] = {}
    follower_of: dict[str, tuple[int, Callable[[float], float]]] = {}
    for link in mapping.links:
        lead, follow = _motor(leader, link.leader), _motor(follower, link.follower)
        low, high = lead.angle_limit
        as_pypot = tuple(follow.to_user(v) for v in follow.angle_limit)  # motor-frame limits
        for limits in (follow.angle_limit, as_pypot):
            ends = sorted((v - link.offset) / link.scale for v in limits)
            low, high = max(low, ends[0]), min(high, ends[1])
        low, high = low + MARGIN_DEG, high - MARGIN_DEG
        middle = (low + high) / 2
        low, high = max(low, middle - HAND_SPAN_DEG), min(high, middle + HAND_SPAN_DEG)
        motor_ends = sorted(lead.to_motor(v) for v in (low, high))
        ranges[link.leader] = (motor_ends[0], motor_ends[1])

        def expected(
            value: float, lead: Motor = lead, follow: Motor = follow, link: Any = link
        ) -> float:
            target = link.apply(lead.to_user(value))
            low, high = follow.angle_limit
            return follow.to_motor(min(max(target, low), high))

        follower_of[link.leader] = (follow.id, expected)
    ids = {link.leader: _motor(leader, link.leader).id for link in mapping.links}
    return ranges, follower_of, ids


@contextmanager
def served(buses: Sequence[VirtualBus]) -> Iterator[list[str]]:
    """Serve buses on ptys; yields their paths."""
    servers = [serve_pty(bus) for bus in buses]
    try:
        yield [server.url for server in servers]
    finally:
        for server in servers:
            server.stop()


def bus_of(config: RobotConfig) -> VirtualBus:
    """The config's (one) bus, emulated with wire timing and 1 ms of adapter latency."""
    buses = virtual_buses(config, wire_timing=True, latency_s=LATENCY_S)
    return next(iter(buses.values()))


class Client:
    """A client process: waits for ``STATE following``, stops on SIGINT, parses its JSON."""

    def __init__(self, args: list[str]) -> None:
        env = dict(os.environ, PYTHONUNBUFFERED="1")
        self.cpu_before = _children_cpu_s()
        self.proc = subprocess.Popen(
            args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=REPO_ROOT, env=env
        )
        self.lines: list[str] = []
        self.following = threading.Event()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stderr is not None
        for line in self.proc.stderr:
            self.lines.append(line.rstrip())
            if line.startswith("STATE following"):
                self.following.set()

    def wait_following(self) -> bool:
        """True once following (False: it failed or took too long)."""
        deadline = time.monotonic() + START_TIMEOUT_S
        while time.monotonic() < deadline and self.proc.poll() is None:
            if self.following.wait(0.1):
                return True
        return False

    def stop(self) -> dict[str, Any]:
        """SIGINT, then its JSON line (``error`` set if none), with ``cpu_s``."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
        try:
            stdout, _ = self.proc.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            stdout, _ = self.proc.communicate()
        record: dict[str, Any]
        try:
            record = json.loads(stdout.strip().splitlines()[-1])
        except (IndexError, ValueError):
            record = {
                "error": f"no JSON line (exit {self.proc.returncode}): "
                + " | ".join(self.lines[-3:])
            }
        record["cpu_s"] = _children_cpu_s() - self.cpu_before
        return record


def _children_cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


@contextmanager
def poppy_server(profile: str, port: str, attempts: int = 3) -> Iterator[str]:
    """``poppy serve --http`` of the follower on ``port``; yields its URL.

    Started again when it fails to find the motors (a ping lost on an overloaded machine).
    """
    for attempt in range(1, attempts + 1):
        proc = subprocess.Popen(
            [
                str(POPPY_CLI),
                "serve",
                "--http",
                "--http-port",
                "0",
                "--profile",
                profile,
                "--port",
                port,
                "--no-sensors",
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            stdin=subprocess.DEVNULL,
        )
        assert proc.stdout is not None and proc.stderr is not None
        url = proc.stdout.readline().strip()
        if url.startswith("http://"):
            break
        error = proc.stderr.read()[-300:].strip()
        proc.wait()
        if attempt == attempts:
            raise RuntimeError(f"poppy serve failed {attempts} times: {error}")
        logger.warning("poppy serve failed (%s): starting it again", error)
    try:
        yield url
    finally:
        interrupt(proc, 20)


def teleop_states(url: str) -> dict[str, str]:
    """The server's teleoperated motors and their state (``GET /api/v1/teleop``)."""
    with urllib.request.urlopen(f"{url}/api/v1/teleop", timeout=2) as answer:
        data = json.load(answer)
    return dict(data)


def _wait_state(url: str, wanted: str, timeout_s: float) -> float | None:
    start = time.perf_counter()
    while time.perf_counter() - start < timeout_s:
        states = teleop_states(url)
        if states and all(s == wanted for s in states.values()):
            return time.perf_counter() - start
        time.sleep(0.005)
    return None


def measure(
    hand: Hand,
    leader: BusProbe,
    follower: BusProbe,
    follower_bus: VirtualBus,
    follower_of: FollowerOf,
    leader_ids: dict[str, int],
    tolerance: float,
    durations: Durations,
) -> dict[str, Any]:
    """Strokes (tracking), then steps (latency and rate); figures seen at the emulators."""
    start = time.perf_counter()
    with Tracker(hand, follower_bus, follower_of) as tracker:
        hand.strokes(durations.strokes_s)
    hand.step(durations.steps)
    end = time.perf_counter()
    found = latencies(hand, leader, follower, leader_ids, follower_of, tolerance)
    return {
        "latency_s": found,
        "steps": durations.steps * len(leader_ids),
        "tracking_rms_deg": tracker.rms(),
        "tracking_rms_by_joint_deg": tracker.rms_by_joint(),
        "tracking_samples": len(tracker.errors),
        "emulator_read_hz": leader.read_rate_hz(start, end),
        "load_avg": os.getloadavg()[0],
    }


def stall(
    hand: Hand,
    proxy: LinkProxy,
    server_url: str,
    follower: BusProbe,
    durations: Durations,
) -> dict[str, Any]:
    """Stall the link while the hand moves; time the hold, then the resume with its ramp."""
    moving = threading.Event()
    strokes = threading.Thread(target=hand.strokes, args=(durations.stall_s + 3.0, moving))
    strokes.start()
    time.sleep(0.5)
    proxy.pause()
    hold_s = _wait_state(server_url, "held", durations.stall_s)
    time.sleep(max(0.0, durations.stall_s - (hold_s or durations.stall_s)))
    resumed_at = time.perf_counter()
    proxy.resume()
    back_s = _wait_state(server_url, "following", 10.0)
    done_at = time.perf_counter()
    moving.set()
    strokes.join()
    by_motor: dict[int, list[float]] = {}
    held: dict[int, float] = {}
    for t, ident, goal in follower.goals:
        if t < resumed_at:
            held[ident] = goal
        elif t <= done_at:
            by_motor.setdefault(ident, []).append(goal)
    steps = [abs(b - a) for goals in by_motor.values() for a, b in itertools.pairwise(goals)]
    first = [abs(goals[0] - held[i]) for i, goals in by_motor.items() if goals and i in held]
    gaps = [abs(goals[-1] - held[i]) for i, goals in by_motor.items() if goals and i in held]
    return {
        "hold_s": hold_s,
        "resume_s": back_s,
        "largest_goal_step_deg": max(steps + first, default=None),
        "gap_at_resume_deg": max(gaps, default=None),
    }
