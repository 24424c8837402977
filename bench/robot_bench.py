"""Robot sync-loop benchmark: poppy and pypot robots built from the same JSON on the same emulator.

For each robot (the Ergo Jr: 6 XL-320, protocol 2; the Humanoid: 25 motors, protocol 1, two
buses through USB2AX adapters), ``poppy emulate --profile NAME --wire-timing --latency-ms 1``
runs in its own process with one pty per controller. Each client (``bench.robot_client`` for
poppy, ``bench/peers/pypot_robot.py`` for pypot) is a subprocess building the robot from the
public Poppy JSON config with its ports replaced by the ptys, and records when each read of the
present registers starts:

* at the config's default loops (present state at 50 Hz): rate, rate error, p99 period jitter;
* with the present loop asked to run at ``TOP_RATE_HZ`` (position, speed and load): the rate
  reached, next to the wire limit computed from packet sizes (``bench.robot_wire``). The top
  rate is measured again on an emulator with no adapter latency (``--latency-ms 0``), to be
  compared with the pure-wire limit.
"""

from __future__ import annotations

import logging
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from bench.clients import run_client
from bench.emulator_proc import EmulatorError, EmulatorProcess
from bench.registry import (
    BENCH_DIR,
    POPPY_CLI,
    POPPY_PYTHON,
    REPO_ROOT,
    BenchContext,
    BenchResult,
    register,
)
from bench.robot_report import build_result
from bench.robot_timing import loop_timing
from bench.robot_wire import ReadGroup, WireLimit, wire_limit

logger = logging.getLogger(__name__)

DEFAULT_HZ = 50.0
TOP_RATE_HZ = 2000.0
LATENCY_MS = 1.0
DURATION_S = 5.0
WARMUP_S = 1.0
# pypot's PosSpeedLoadDxlController reads these three at 50 Hz in both of its sync loops.
PYPOT_READS = "position, speed, load"


@dataclass(frozen=True)
class RobotSpec:
    """A robot: its emulator profile and the pypot JSON config both libraries load."""

    key: str
    label: str
    profile: str
    config: Path


ROBOTS = (
    RobotSpec(
        "ergo-jr",
        "Ergo Jr (6 × XL-320, protocol 2)",
        "ergo-jr",
        REPO_ROOT / "tests" / "robot" / "data" / "poppy_ergo_jr.json",
    ),
    RobotSpec(
        "humanoid",
        "Humanoid (25 × MX-28/MX-64/AX-12, protocol 1, two USB2AX buses)",
        "humanoid",
        REPO_ROOT / "tests" / "robot" / "data" / "poppy_humanoid.json",
    ),
)


class ProfileEmulator(EmulatorProcess):
    """``poppy emulate --profile NAME``: one pty per controller, printed one per line in order.

    Attributes:
        ports: controller name -> pty path, once started.
    """

    def __init__(self, profile: str, controllers: list[str], *, latency_ms: float) -> None:
        """Prepare (not start) the emulator of ``profile`` whose controllers are ``controllers``."""
        super().__init__(f"profile {profile}", latency_ms=latency_ms)
        self._args = [str(POPPY_CLI), "emulate", "--profile", profile]
        self._args += ["--wire-timing", "--latency-ms", str(latency_ms)]
        self.controllers = controllers
        self.ports: dict[str, str] = {}

    def start(self) -> str:
        """Start the process and read one pty path per controller.

        Raises:
            EmulatorError: it printed no port in time, or exited before printing them all.
        """
        lines = [super().start()]
        assert self._proc is not None and self._proc.stdout is not None
        while len(lines) < len(self.controllers):
            # The ports are printed and flushed together, so the next lines may already sit in
            # the text buffer, where select() cannot see them: read them directly.
            line = self._proc.stdout.readline().strip()
            if not line:
                self.stop()
                raise EmulatorError(f"`{self.command}` printed {len(lines)} ports")
            lines.append(line)
        self.ports = dict(zip(self.controllers, lines, strict=True))
        return lines[0]


def _controllers(spec: RobotSpec) -> dict[str, Any]:
    """Controller name -> (protocol, baud rate, sync read, read groups) of the robot's config."""
    from poppy_core.models import model_by_name
    from poppy_core.robot import load_config, load_profile
    from poppy_core.robot import registers as regs

    config = load_config(spec.config)
    profile = load_profile(spec.profile)
    if list(profile.controllers) != list(config.controllers):
        raise EmulatorError(f"profile {spec.profile} and {spec.config.name} differ in controllers")
    out: dict[str, Any] = {}
    for name, controller in config.controllers.items():
        motors = config.motors_of_controller(name)
        if [config.motors[m].id for m in motors] != [
            profile.motors[m].id for m in profile.motors_of_controller(name)
        ]:
            raise EmulatorError(f"profile {spec.profile} puts other motors on {name}")
        layouts: dict[tuple[int, int], int] = defaultdict(int)
        for motor in motors:
            for block in regs.read_blocks(model_by_name(config.motors[motor].type), regs.PRESENT):
                layouts[(block.address, block.length)] += 1
        groups = [ReadGroup(count, length) for (_, length), count in layouts.items()]
        out[name] = {
            "protocol": controller.protocol,
            "baudrate": controller.baudrate,
            "sync_read": bool(controller.sync_read),
            "motors": len(motors),
            "groups": groups,
        }
    return out


def _argv(
    client: str, spec: RobotSpec, ports: dict[str, str], top: bool, ctx: BenchContext
) -> list[str]:
    options = ["--config", str(spec.config)]
    for name, port in ports.items():
        options += ["--port", f"{name}={port}"]
    options += ["--duration-s", str(DURATION_S), "--warmup-s", str(WARMUP_S)]
    if top:
        options += ["--rate-hz", str(TOP_RATE_HZ)]
    if client == "poppy":
        return [str(POPPY_PYTHON), "-m", "bench.robot_client", *options]
    assert ctx.peers_python is not None
    return [str(ctx.peers_python), str(BENCH_DIR / "peers" / "pypot_robot.py"), *options]


def _measure(
    client: str,
    spec: RobotSpec,
    emu: ProfileEmulator,
    top: bool,
    latency_ms: float,
    ctx: BenchContext,
) -> list[dict[str, Any]]:
    """Run one client once; one entry per controller (or one entry saying what failed)."""
    emu_cpu = emu.cpu_s()
    run = run_client(_argv(client, spec, emu.ports, top, ctx))
    emu_cpu = emu.cpu_s() - emu_cpu
    common = {
        "robot": spec.key,
        "client": client,
        "mode": "top" if top else "default",
        "latency_ms": latency_ms,
        "wall_s": run.wall_s,
        "cpu_s": run.cpu_s,
        "emulator_cpu_s": emu_cpu,
        "loop_cpu_pct": run.record.get("loop_cpu_pct"),
        "setup_s": run.record.get("setup_s"),
        "version": run.record.get("version"),
    }
    error = run.record.get("error")
    found = run.record.get("controllers") or {}
    if error or set(found) != set(emu.ports):
        problem = error or f"controllers {sorted(found)}, expected {sorted(emu.ports)}"
        logger.info("%s %s %s: %s", client, spec.key, common["mode"], problem)
        failed = {"controller": None, "all_controllers": list(emu.ports)}
        return [{**common, **failed, "ok": False, "problem": problem}]
    entries = []
    for name, data in found.items():
        timing = loop_timing(data["starts_s"], None if top else DEFAULT_HZ)
        extra = {k: v for k, v in data.items() if k != "starts_s"}
        entries.append(
            {
                **common,
                "controller": name,
                "ok": timing["error"] is None,
                "problem": timing["error"],
                "timing": timing,
                "detail": extra,
            }
        )
        logger.info(
            "%s %s %s (latency %g ms) %s: %s",
            client,
            spec.key,
            common["mode"],
            latency_ms,
            name,
            timing["error"] or f"{timing['rate_hz']:.1f} Hz, p99 {timing['jitter_p99_ms']:.3f} ms",
        )
    return entries


def _run_robot(
    spec: RobotSpec, ctx: BenchContext, runs: list[dict[str, Any]], emulators: list[dict[str, Any]]
) -> None:
    controllers = list(_controllers(spec))
    clients = ["poppy", "pypot"] if ctx.peers_python is not None else ["poppy"]
    for latency_ms, modes in ((LATENCY_MS, (False, True)), (0.0, (True,))):
        emu = ProfileEmulator(spec.profile, controllers, latency_ms=latency_ms)
        emu.start()
        emulators.append({"robot": spec.key, "command": emu.command, "ports": dict(emu.ports)})
        try:
            for rep in range(ctx.repeat):
                for top in modes:
                    for client in clients:
                        for entry in _measure(client, spec, emu, top, latency_ms, ctx):
                            runs.append({"rep": rep, **entry})
        finally:
            emu.stop()


def _limits(spec: RobotSpec) -> dict[str, dict[str, Any]]:
    out = {}
    for name, info in _controllers(spec).items():
        limit: WireLimit = wire_limit(
            info["protocol"], info["groups"], info["baudrate"], sync_read=info["sync_read"]
        )
        out[name] = {
            "motors": info["motors"],
            "protocol": info["protocol"],
            "read_bytes": [g.length for g in info["groups"]],
            "method": limit.method,
            "bus_bytes": limit.bus_bytes,
            "host_bytes": limit.host_bytes,
            "wire_s": limit.wire_s,
            "wire_hz": limit.wire_hz,
            "emulated_hz": {
                str(LATENCY_MS): limit.emulated_hz(LATENCY_MS / 1000.0),
                "0.0": limit.emulated_hz(0.0),
            },
        }
    return out


def _poppy_reads(spec: RobotSpec) -> str:
    """What poppy's default present loop reads for this robot's config (``position, speed``)."""
    from poppy_core.robot import load_config, loops_for

    config = load_config(spec.config)
    syncloop = next(iter(config.controllers.values())).syncloop
    present = next(s for s in loops_for(syncloop) if s.name == "present")
    return ", ".join(r.removeprefix("present_") for r in present.registers)


@register("robot", "Ergo Jr and Humanoid sync loops: 50 Hz rate/jitter and top rate vs pypot")
def robot_benchmark(ctx: BenchContext) -> BenchResult:
    """Run the robot sync-loop benchmark (see the module docstring).

    Args:
        ctx: repeat count and the peers' interpreter.

    Returns:
        Tables, notes and raw runs for docs/performance.md and bench/results/robot.json.
    """
    runs: list[dict[str, Any]] = []
    emulators: list[dict[str, Any]] = []
    errors: list[str] = []
    limits: dict[str, dict[str, dict[str, Any]]] = {}
    for spec in ROBOTS:
        try:
            limits[spec.key] = _limits(spec)
            _run_robot(spec, ctx, runs, emulators)
        except EmulatorError as exc:
            errors.append(f"{spec.key}: {exc}")
    return build_result(
        robots=[
            {
                "key": r.key,
                "label": r.label,
                "config": r.config.name,
                "top_hz": TOP_RATE_HZ,
                "reads": {"poppy": _poppy_reads(r), "pypot": PYPOT_READS},
            }
            for r in ROBOTS
        ],
        limits=limits,
        emulators=emulators,
        runs=runs,
        errors=errors,
        peers_note=ctx.peers_note,
        repeat=ctx.repeat,
        settings={
            "default_hz": DEFAULT_HZ,
            "top_rate_hz": TOP_RATE_HZ,
            "latency_ms": LATENCY_MS,
            "duration_s": DURATION_S,
            "warmup_s": WARMUP_S,
        },
    )
