"""`poppy doctor`'s checks of the bus and motors: one line each, with the command that fixes it.

The adapter (there, and readable: the dialout group), its FTDI latency timer, every motor of
the profile (present, model, ID, rate, return delay, angle limits, firmware), duplicated IDs,
voltage and temperature. The machine's own checks (camera, service, page, disk) are in
``poppy_core.robot.doctor_system``; :func:`run_doctor` runs them all.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Literal

from poppy_core.bus.dxlbus import DxlBus
from poppy_core.bus.groupread import count_answers
from poppy_core.bus.ports import DIALOUT_ADVICE, latency_advice, latency_timer_path
from poppy_core.bus.ports import read_ftdi_latency_ms as read_latency
from poppy_core.bus.scan import scan
from poppy_core.bus.timing import reply_floor_s
from poppy_core.errors import CorruptPacketError, PoppyError
from poppy_core.models import ServoModel
from poppy_core.robot.config import RobotConfig
from poppy_core.robot.guided_setup import (
    REPLY_TIMEOUT_S,
    MotorTarget,
    motor_targets,
    read_settings,
)

logger = logging.getLogger(__name__)

Status = Literal["pass", "fail", "skip"]
GOOD_LATENCY_MS = 1
LATE_REPLIES_S = 0.1
"""How long the line is listened to after the broadcast ping, for replies still coming."""


@dataclass(frozen=True)
class Check:
    """One check: what was checked, how it went, what was seen, and the command that fixes it.

    Attributes:
        name: what was checked (``"adapter"``, ``"m3"``, ``"camera"``...).
        status: ``"pass"``, ``"fail"`` or ``"skip"`` (not applicable here; the reason says why).
        detail: what was seen, or why it was skipped.
        fix: the command (or step) that fixes a failure, None when there is nothing to do.
    """

    name: str
    status: Status
    detail: str
    fix: str | None = None

    def as_dict(self) -> dict[str, object]:
        return {"name": self.name, "status": self.status, "detail": self.detail, "fix": self.fix}


@dataclass
class DoctorReport:
    """Every check, in the order run; ``ok`` when none failed."""

    checks: list[Check] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return all(c.status != "fail" for c in self.checks)

    def as_dict(self) -> dict[str, object]:
        """The shape of `poppy doctor --json`."""
        return {"ok": self.ok, "checks": [c.as_dict() for c in self.checks]}


def check_adapter(port: str | None, access: Callable[[str, int], bool] = os.access) -> Check:
    """The adapter is there and this user may read and write it."""
    if port is None:
        return Check(
            "adapter",
            "fail",
            "no serial port found",
            "plug the USB adapter (USB2AX, U2D2) and power, then `poppy ports`",
        )
    if "://" in port:
        return Check("adapter", "pass", f"{port} (not a local serial device)")
    if not os.path.exists(port):
        return Check("adapter", "fail", f"{port} does not exist", "`poppy ports` lists the ports")
    if not access(port, os.R_OK | os.W_OK):
        return Check("adapter", "fail", f"{port}: permission denied", DIALOUT_ADVICE)
    return Check("adapter", "pass", f"{port} readable and writable")


def check_latency(port: str | None, sysfs_root: str = "/sys") -> Check:
    """The FTDI latency timer of the adapter: 1 ms good, the kernel's 16 ms slows every read."""
    if port is None or "://" in port:
        return Check("latency timer", "skip", "no local serial adapter")
    latency = read_latency(port, sysfs_root=sysfs_root)
    if latency is None:
        where = latency_timer_path(port, sysfs_root)
        return Check("latency timer", "skip", f"not an FTDI adapter ({where} absent)")
    advice = latency_advice(port, latency)
    if advice is None:
        return Check("latency timer", "pass", f"{latency} ms")
    fix = advice.split(": ", 1)[1]
    return Check("latency timer", "fail", f"{latency} ms (want {GOOD_LATENCY_MS} ms)", fix)


def _setup_fix(profile: str, port: str, motor: str) -> str:
    return (
        f"plug only {motor}, then: poppy setup motors --profile {profile} --port {port} "
        f"--motors {motor}"
    )


def check_motor(bus: DxlBus, target: MotorTarget, profile: str, port: str) -> list[Check]:
    """One profile motor: present with its model and ID at the profile's rate, its return
    delay, angle limits and firmware, voltage and temperature."""
    name = f"{target.name} (ID {target.id})"
    try:
        pinged = bus.ping(target.id)
    except CorruptPacketError:
        pinged = None
    if pinged is None:
        return [
            Check(
                name,
                "fail",
                f"no {target.model} answers as ID {target.id} at {target.baudrate} bps, "
                f"protocol {target.protocol}",
                _setup_fix(profile, port, target.name),
            )
        ]
    if pinged.model is None or pinged.model.name != target.model:
        found = pinged.model_name or f"model number {pinged.model_number}"
        return [
            Check(
                name,
                "fail",
                f"ID {target.id} is a {found}, {target.name} is a {target.model}",
                f"plug a {target.model} as {target.name}: "
                + _setup_fix(profile, port, target.name),
            )
        ]
    model = pinged.model
    settings = read_settings(bus, target.id, model)
    step = model.position_range_deg / model.resolution
    checks: list[Check] = []
    delay = settings["return_delay_time"]
    if abs(delay - target.return_delay_us) >= 1.0:
        checks.append(
            Check(
                name,
                "fail",
                f"return delay {delay:g} µs (want {target.return_delay_us:g} µs)",
                f"poppy motor set-return-delay {target.id} {target.return_delay_us:g} "
                f"--port {port}",
            )
        )
    low, high = target.angle_limits
    held = settings["min_position_limit"], settings["max_position_limit"]
    if abs(held[0] - low) > step or abs(held[1] - high) > step:
        checks.append(
            Check(
                name,
                "fail",
                f"angle limits {held[0]:.1f}° .. {held[1]:.1f}° (want {low:.1f}° .. {high:.1f}°)",
                f"poppy motor angle-limits {target.id} {low:g} {high:g} --port {port}",
            )
        )
    checks.extend(_health(bus, target, model, name))
    if not checks:
        checks.append(
            Check(
                name,
                "pass",
                f"{model.name} at {target.baudrate} bps, firmware {pinged.firmware}, return "
                f"delay {delay:g} µs, limits {held[0]:.1f}° .. {held[1]:.1f}°",
            )
        )
    return checks


def _health(bus: DxlBus, target: MotorTarget, model: ServoModel, name: str) -> list[Check]:
    """Voltage within the motor's own limits, temperature below its limit."""
    read = {
        n: float(bus.read_register(target.id, model, n))
        for n in (
            "present_voltage",
            "min_voltage_limit",
            "max_voltage_limit",
            "present_temperature",
            "temperature_limit",
        )
    }
    checks = []
    volts, low, high = read["present_voltage"], read["min_voltage_limit"], read["max_voltage_limit"]
    if not low <= volts <= high:
        checks.append(
            Check(
                name,
                "fail",
                f"voltage {volts:.1f} V outside {low:.1f}-{high:.1f} V",
                "check the power supply (an Ergo Jr's XL-320 want 7.5 V)",
            )
        )
    temp, limit = read["present_temperature"], read["temperature_limit"]
    if temp >= limit:
        checks.append(
            Check(
                name,
                "fail",
                f"temperature {temp:.0f} °C at its limit {limit:.0f} °C",
                "let it cool (poppy robot compliant on), then look for a blocked joint",
            )
        )
    return checks


def check_duplicates(bus: DxlBus, targets: list[MotorTarget], profile: str, port: str) -> Check:
    """No ID answered twice (two motors sharing an ID both answer a broadcast ping)."""
    if not bus.proto.has_broadcast_ping:
        return Check("duplicated IDs", "skip", "protocol 1 has no broadcast ping to count replies")
    counts = count_answers(bus)
    shared = sorted(i for i, n in counts.items() if n > 1)
    if not shared:
        return Check("duplicated IDs", "pass", f"{len(counts)} ID(s), each answered once")
    names = {t.id: t.name for t in targets}
    listed = ", ".join(f"ID {i} ({counts[i]} motors)" for i in shared)
    first = names.get(shared[0], "the motor")
    return Check(
        "duplicated IDs",
        "fail",
        listed,
        "unplug all but one of them; " + _setup_fix(profile, port, first),
    )


def check_motors(config: RobotConfig, profile: str, port: str | None) -> list[Check]:
    """Every motor of the profile, on ``port``, at its controller's rate and protocol."""
    targets = motor_targets(config)
    if port is None:
        return [Check("motors", "skip", "no adapter to reach them")]
    checks: list[Check] = []
    by_bus: dict[tuple[int, int], list[MotorTarget]] = {}
    for target in targets:
        by_bus.setdefault((target.baudrate, target.protocol), []).append(target)
    floor = max(REPLY_TIMEOUT_S, reply_floor_s())
    for (rate, protocol), group in by_bus.items():
        try:
            with DxlBus(port, rate, protocol, retries=2, min_timeout_s=floor) as bus:
                bus.adaptive_latency = True  # a slow adapter is learned from its late replies
                checks.append(check_duplicates(bus, group, profile, port))
                for target in group:
                    checks.extend(check_motor(bus, target, profile, port))
        except PoppyError as exc:
            checks.append(
                Check("motors", "fail", f"{port} at {rate} bps: {exc}", "`poppy ports`, then retry")
            )
            continue
        checks = _where_missing(checks, group, port, protocol)
    return checks


def _where_missing(
    checks: list[Check], group: list[MotorTarget], port: str, protocol: int
) -> list[Check]:
    """Say where the missing motors of ``group`` answer, if anywhere at another rate (a scan
    of their IDs at every standard rate of the protocol)."""
    missing = {
        f"{t.name} (ID {t.id})": t
        for t in group
        if any(c.name == f"{t.name} (ID {t.id})" and c.detail.startswith("no ") for c in checks)
    }
    if not missing:
        return checks
    try:
        found = scan(port, None, [protocol], sorted({t.id for t in missing.values()}))
    except PoppyError as exc:
        logger.info("could not look for the missing motors on %s: %s", port, exc)
        return checks
    rates: dict[int, list[int]] = {}
    for motor in found:
        rates.setdefault(motor.id, []).append(motor.baudrate)
    out = []
    for check in checks:
        target = missing.get(check.name)
        if target is not None and target.id in rates and check.detail.startswith("no "):
            where = ", ".join(f"{r} bps" for r in rates[target.id])
            check = replace(check, detail=f"{check.detail}; ID {target.id} answers at {where}")
        out.append(check)
    return out
