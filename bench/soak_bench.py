"""Fault soak: an Ergo Jr and a Humanoid under faults for minutes, poppy and pypot side by side.

For each robot, ``poppy emulate --profile NAME --wire-timing --latency-ms 1 --control --link
...`` runs in its own process (one pty per controller, each behind a symlink that follows the
pty when the line is lost and comes back, as ``/dev/serial/by-id`` does). A client builds the
robot from the public Poppy JSON config on those links, runs its sync loops (50 Hz) and a
``Sinus`` primitive on every motor, and says ``ready``. From then on this process drives the
faults through the emulator's stdin (the commands of ``poppy emulate --control``, the same
knobs as its flags):

* ``corrupt 0.01`` and ``drop 0.01`` for the whole run (1 % of reply bytes get a bit flipped,
  1 % of replies are lost);
* every ``UNPLUG_EVERY_S`` one motor is unplugged for ``UNPLUG_FOR_S`` (motors taken in turn);
* every ``LOSE_EVERY_S`` one bus is lost for ``LOSE_FOR_S`` (buses taken in turn).

After ``minutes`` the client is told to stop, closes the robot and prints what it saw
(``bench.soak_client``, ``bench/peers/pypot_soak.py``). The faults start once the robot is
built: pypot's start-up scan gives up on a single lost reply. ``bench.soak_report`` turns the
records and the fault times (one monotonic clock for all processes) into the report.

The benchmark also runs pypot's own IO toggling the torque of the Ergo Jr (flush before every
packet) against ``poppy emulate`` and ``poppy sim`` and counts lost writes
(``bench/peers/pypot_torque.py``).
"""

from __future__ import annotations

import json
import logging
import os
import select
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from bench.clients import run_client
from bench.emulator_proc import EmulatorError
from bench.procs import interrupt
from bench.registry import (
    BENCH_DIR,
    POPPY_CLI,
    POPPY_PYTHON,
    REPO_ROOT,
    BenchContext,
    BenchResult,
    register,
)
from bench.robot_bench import ROBOTS, ProfileEmulator, RobotSpec
from bench.soak_report import FaultEvent, build_result

logger = logging.getLogger(__name__)

DEFAULT_MINUTES = 10.0
LATENCY_MS = 1.0
CORRUPT = 0.01
DROP = 0.01
UNPLUG_FIRST_S, UNPLUG_EVERY_S, UNPLUG_FOR_S = 15.0, 30.0, 5.0
LOSE_FIRST_S, LOSE_EVERY_S, LOSE_FOR_S = 55.0, 60.0, 2.0
TAIL_S = 3.0  # no fault starts this close to the end: its recovery is measured too
READY_TIMEOUT_S = 180.0
STOP_TIMEOUT_S = 60.0
TORQUE_CYCLES = 834  # x 2 toggles x 6 motors = 10,008 writes


class FaultEmulator(ProfileEmulator):
    """``poppy emulate --profile NAME`` with ``--control`` and one ``--link`` per controller."""

    stdin = subprocess.PIPE

    def __init__(self, spec: RobotSpec, controllers: list[str], links: Path) -> None:
        super().__init__(spec.profile, controllers, latency_ms=LATENCY_MS)
        self._args += ["--control", "--seed", "1"]
        for name in controllers:
            self._args += ["--link", str(links / name)]

    def send(self, command: str) -> float:
        """Write one fault command; return when it was written (monotonic clock)."""
        assert self._proc is not None and self._proc.stdin is not None
        self._proc.stdin.write(command + "\n")
        self._proc.stdin.flush()
        return time.monotonic()


@dataclass(frozen=True)
class Planned:
    """A fault command due ``at_s`` after the client is ready."""

    at_s: float
    command: str
    kind: str  # "unplug" or "lose"
    target: str  # motor id or bus name
    duration_s: float


def plan(controllers: dict[str, list[int]], duration_s: float) -> list[Planned]:
    """The fault schedule of one run (see the module doc)."""
    ids = [i for motors in controllers.values() for i in motors]
    # Every 7th motor in turn, so that a robot with several buses has each of them unplugged.
    order = [ids[(k * 7) % len(ids)] for k in range(len(ids))]
    events: list[Planned] = []
    t, k = UNPLUG_FIRST_S, 0
    while t + UNPLUG_FOR_S + TAIL_S <= duration_s:
        motor = order[k % len(order)]
        events.append(
            Planned(t, f"unplug {motor} {UNPLUG_FOR_S:g}", "unplug", str(motor), UNPLUG_FOR_S)
        )
        t, k = t + UNPLUG_EVERY_S, k + 1
    buses = list(controllers)
    t, k = LOSE_FIRST_S, 0
    while t + LOSE_FOR_S + TAIL_S <= duration_s:
        bus = buses[k % len(buses)]
        events.append(Planned(t, f"lose {LOSE_FOR_S:g} {bus}", "lose", bus, LOSE_FOR_S))
        t, k = t + LOSE_EVERY_S, k + 1
    return sorted(events, key=lambda e: e.at_s)


def _read_ready(proc: subprocess.Popen[str]) -> float:
    """Wait for the client's ``ready T`` line; return T.

    Raises:
        EmulatorError: the client ended or printed its error record (given) instead.
    """
    assert proc.stdout is not None
    end = time.monotonic() + READY_TIMEOUT_S
    while time.monotonic() < end:
        ready, _, _ = select.select([proc.stdout], [], [], 1.0)
        if ready:
            line = proc.stdout.readline()
            if not line:
                break
            if line.startswith("ready "):
                return float(line.split()[1])
            if line.startswith("{"):
                raise EmulatorError(str(json.loads(line).get("error")))
        if proc.poll() is not None:
            break
    raise EmulatorError("the client did not get ready")


def soak_session(
    client: list[str], emulator: FaultEmulator, controllers: dict[str, list[int]], minutes: float
) -> tuple[dict[str, Any], list[FaultEvent]]:
    """Run one client under the fault schedule; its record and the faults as injected."""
    duration_s = minutes * 60.0
    events: list[FaultEvent] = []
    with tempfile.TemporaryFile("w+") as errors:
        proc = subprocess.Popen(
            client,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=errors,
            text=True,
            cwd=REPO_ROOT,
        )
        try:
            t0 = _read_ready(proc)
        except EmulatorError as exc:
            proc.kill()
            _, _ = proc.communicate()
            errors.seek(0)
            tail = (errors.read().strip().splitlines() or [str(exc)])[-1]
            return {"error": f"not ready: {tail}"}, events
        emulator.send(f"corrupt {CORRUPT:g}")
        emulator.send(f"drop {DROP:g}")
        for item in plan(controllers, duration_s):
            time.sleep(max(0.0, t0 + item.at_s - time.monotonic()))
            sent = emulator.send(item.command)
            events.append(FaultEvent(sent - t0, item.kind, item.target, item.duration_s))
        time.sleep(max(0.0, t0 + duration_s - time.monotonic()))
        emulator.send("corrupt 0")
        emulator.send("drop 0")
        assert proc.stdin is not None
        proc.stdin.write("stop\n")
        proc.stdin.flush()
        try:
            out, _ = proc.communicate(timeout=STOP_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            proc.kill()
            out, _ = proc.communicate()
        lines = [line for line in out.splitlines() if line.startswith("{")]
        if not lines:
            errors.seek(0)
            tail = (errors.read().strip().splitlines() or [f"exit {proc.returncode}"])[-1]
            return {"error": f"no JSON: {tail}"}, events
        record: dict[str, Any] = json.loads(lines[-1])
        errors.seek(0)
        record["stderr_lines"] = len(errors.read().splitlines())
    return record, events


def _robot_controllers(spec: RobotSpec) -> dict[str, list[int]]:
    from poppy_core.robot import load_config

    config = load_config(spec.config)
    return {
        name: [config.motors[m].id for m in config.motors_of_controller(name)]
        for name in config.controllers
    }


def soak_robot(spec: RobotSpec, ctx: BenchContext, minutes: float) -> dict[str, Any]:
    """poppy then pypot on one robot, each on a fresh emulator; their records and faults."""
    controllers = _robot_controllers(spec)
    runs: dict[str, Any] = {}
    peers: list[tuple[str, list[str]]] = [("poppy", [str(POPPY_PYTHON), "-m", "bench.soak_client"])]
    if ctx.peers_python is not None:
        peers.append(("pypot", [str(ctx.peers_python), str(BENCH_DIR / "peers" / "pypot_soak.py")]))
    for peer, command in peers:
        with tempfile.TemporaryDirectory(prefix="poppy-soak-") as links:
            emulator = FaultEmulator(spec, list(controllers), Path(links))
            logger.info("soak %s with %s for %g min", spec.key, peer, minutes)
            try:
                with emulator:
                    args = [*command, "--config", str(spec.config)]
                    for name in controllers:
                        args += ["--port", f"{name}={Path(links) / name}"]
                    record, events = soak_session(args, emulator, controllers, minutes)
            except EmulatorError as exc:
                record, events = {"error": str(exc)}, []
            runs[peer] = {"record": record, "events": [vars(e) for e in events]}
            if record.get("error"):
                logger.warning("%s on %s: %s", peer, spec.key, record["error"])
    return {"label": spec.label, "controllers": controllers, "runs": runs}


def torque_toggles(ctx: BenchContext) -> dict[str, Any]:
    """pypot's Dxl320IO toggling the Ergo Jr's torque on `poppy emulate` and `poppy sim`."""
    if ctx.peers_python is None:
        return {"error": "peers venv unavailable"}
    out: dict[str, Any] = {}
    for label, args in (
        ("poppy emulate --profile ergo-jr", ["emulate", "--profile", "ergo-jr"]),
        ("poppy sim --profile ergo-jr --pty", ["sim", "--profile", "ergo-jr", "--pty"]),
    ):
        proc = subprocess.Popen(
            [str(POPPY_CLI), *args],
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            stdin=subprocess.DEVNULL,
            text=True,
        )
        try:
            assert proc.stdout is not None
            ready, _, _ = select.select([proc.stdout], [], [], 60.0)
            port = proc.stdout.readline().strip() if ready else ""
            if not port:
                out[label] = {"error": "no port printed"}
                continue
            client = [
                str(ctx.peers_python),
                str(BENCH_DIR / "peers" / "pypot_torque.py"),
                "--port",
                port,
                "--cycles",
                str(TORQUE_CYCLES),
            ]
            load_before = os.getloadavg()[0]
            record = run_client(client).record
            record["load_1min"] = [round(load_before, 2), round(os.getloadavg()[0], 2)]
            # The control: the same client without its output flush, so that what the kernel
            # discards at that flush is told apart from what the emulator loses.
            record["control"] = run_client([*client, "--keep-output"]).record
            out[label] = record
        finally:
            interrupt(proc)
    return out


@register("soak", "Ergo Jr and Humanoid under faults for minutes; pypot side by side", long=True)
def soak(ctx: BenchContext) -> BenchResult:
    """Run the soak (``--minutes`` per robot and client, default 10) and the torque toggles."""
    minutes = ctx.minutes if ctx.minutes is not None else DEFAULT_MINUTES
    if not POPPY_CLI.exists():
        raise EmulatorError(f"{POPPY_CLI} is missing: run `make test` first")
    load_start = os.getloadavg()
    robots = {spec.key: soak_robot(spec, ctx, minutes) for spec in ROBOTS}
    toggles = torque_toggles(ctx)
    raw = {
        "minutes": minutes,
        "plan": {
            "corrupt": CORRUPT,
            "drop": DROP,
            "latency_ms": LATENCY_MS,
            "unplug": [UNPLUG_FIRST_S, UNPLUG_EVERY_S, UNPLUG_FOR_S],
            "lose": [LOSE_FIRST_S, LOSE_EVERY_S, LOSE_FOR_S],
        },
        "load_1min": [round(load_start[0], 2), round(os.getloadavg()[0], 2)],
        "robots": robots,
        "torque": toggles,
        "peers_note": ctx.peers_note,
    }
    return build_result(raw)
