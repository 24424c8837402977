"""Build virtual buses from a short text spec ("MX-28:11-15,AX-12A:36-37") or a robot preset."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

from poppy_core.emulator.bus import Adapter, VirtualBus
from poppy_core.emulator.motor import VirtualMotor
from poppy_core.errors import ConfigError, RegisterError, UnknownModelError
from poppy_core.models import ServoModel, model_by_name

_IDS = re.compile(r"^\s*(\d+)\s*(?:-\s*(\d+)\s*)?$")
# ``1*6``: six motors sharing ID 1, as a kit of new motors comes (each at its factory ID)
_REPEAT = re.compile(r"^\s*(\d+)\s*\*\s*(\d+)\s*$")
_MAX_REPEAT = 253
_MAX_MOTOR_ID = 252


def _parse_ids(text: str, spec: str, shared: set[int], plain: list[int]) -> list[int]:
    """The IDs of ``text``; IDs given as ``ID*COUNT`` are added to ``shared``, the others to
    ``plain``."""
    ids: list[int] = []
    for part in re.split(r"[+/ ]+", text.strip()):
        if not part:
            continue
        repeat = _REPEAT.match(part)
        if repeat is not None:
            motor_id, count = int(repeat.group(1)), int(repeat.group(2))
            if motor_id > _MAX_MOTOR_ID or not 1 <= count <= _MAX_REPEAT:
                raise ConfigError(
                    f"bad repeat {part!r} in emulator spec {spec!r} (ID*COUNT: ID 0..."
                    f"{_MAX_MOTOR_ID}, COUNT 1..{_MAX_REPEAT})",
                    field="spec",
                    value=spec,
                    reason="bad repeat",
                )
            ids.extend([motor_id] * count)
            shared.add(motor_id)
            continue
        match = _IDS.match(part)
        if match is None:
            raise ConfigError(
                f"bad id list {text!r} in emulator spec {spec!r} (expected e.g. 1-6 or 3)",
                field="spec",
                value=spec,
                reason="bad id list",
            )
        first = int(match.group(1))
        last = int(match.group(2) or first)
        if last < first or last > _MAX_MOTOR_ID:
            raise ConfigError(
                f"bad id range {part!r} in emulator spec {spec!r} (ids are 0..{_MAX_MOTOR_ID})",
                field="spec",
                value=spec,
                reason="bad id range",
            )
        ids.extend(range(first, last + 1))
        plain.extend(range(first, last + 1))
    return ids


def parse_spec(spec: str) -> list[tuple[ServoModel, int]]:
    """Parse ``"MODEL:IDS,MODEL:IDS"`` into ``(model, id)`` pairs.

    IDS is a single id or a range ``a-b``; several are joined with ``+`` or ``/``; a bare id
    list after a comma continues the previous model (``"MX-28:1,2,5-6"``). ``ID*COUNT`` gives
    COUNT motors sharing that ID (``"XL-320:1*6"``: a kit of new motors, all at ID 1; the
    emulator's control tells them apart by their place, ``plug #3``).

    Raises:
        ConfigError: empty spec, unknown model, bad or duplicate ids.
    """
    pairs: list[tuple[ServoModel, int]] = []
    model: ServoModel | None = None
    shared: set[int] = set()
    plain: list[int] = []
    for item in spec.split(","):
        item = item.strip()
        if not item:
            continue
        if ":" in item:
            name, _, ids_text = item.rpartition(":")
            try:
                model = model_by_name(name.strip())
            except UnknownModelError as exc:
                raise ConfigError(
                    f"unknown model {name.strip()!r} in emulator spec {spec!r}: {exc}",
                    field="spec",
                    value=spec,
                    reason="unknown model",
                ) from exc
        elif model is None:
            raise ConfigError(
                f"emulator spec {spec!r} must start with MODEL:IDS (e.g. XL-320:1-6)",
                field="spec",
                value=spec,
                reason="missing model",
            )
        else:
            ids_text = item
        pairs.extend((model, motor_id) for motor_id in _parse_ids(ids_text, spec, shared, plain))
    if not pairs:
        raise ConfigError(
            f"emulator spec {spec!r} lists no motor", field="spec", value=spec, reason="empty"
        )
    seen: set[int] = set()
    for motor_id in [*plain, *shared]:
        if motor_id in seen:
            raise ConfigError(
                f"id {motor_id} appears twice in emulator spec {spec!r} (motors sharing an ID: "
                "ID*COUNT, e.g. XL-320:1*6)",
                field="spec",
                value=spec,
                reason="duplicate id",
            )
        seen.add(motor_id)
    return pairs


def build_bus_from_spec(
    spec: str,
    protocol: int | None = None,
    baudrate: int = 1_000_000,
    **bus_options: Any,
) -> VirtualBus:
    """Build a :class:`VirtualBus` from a spec such as ``"MX-28:11-15,AX-12A:36-37"``.

    Args:
        spec: models and ids (see :func:`parse_spec`).
        protocol: bus protocol; None takes the models' (they must all agree).
        baudrate: every motor's baud rate, and the bus's default line speed.
        **bus_options: passed to :class:`VirtualBus` (``wire_timing``, ``latency_s``,
            ``plant``, ``adapter``, ``seed``, ``auto_step``, ``clock``).

    Raises:
        ConfigError: bad spec, mixed protocols, or a baud rate a model cannot use.
    """
    pairs = parse_spec(spec)
    protocols = {model.protocol for model, _ in pairs}
    if protocol is None:
        if len(protocols) > 1:
            raise ConfigError(
                f"emulator spec {spec!r} mixes protocol 1 and 2 models; one bus speaks one",
                field="spec",
                value=spec,
                reason="mixed protocols",
            )
        protocol = protocols.pop()
    motors: list[VirtualMotor] = []
    for model, motor_id in pairs:
        if model.protocol != protocol:
            raise ConfigError(
                f"{model.name} speaks protocol {model.protocol}, not {protocol}",
                field="protocol",
                value=protocol,
                reason="protocol mismatch",
            )
        try:
            motors.append(VirtualMotor(model, motor_id, baudrate))
        except RegisterError as exc:
            raise ConfigError(
                f"{model.name} cannot run at {baudrate} bps: {exc}",
                field="baudrate",
                value=baudrate,
                reason="unsupported baud rate",
            ) from exc
    return VirtualBus(motors, protocol, baudrate=baudrate, **bus_options)


def ergo_jr_bus(**bus_options: Any) -> VirtualBus:
    """The Poppy Ergo Jr's bus: six XL-320, ids 1 to 6, protocol 2, 1 Mbps."""
    return build_bus_from_spec("XL-320:1-6", protocol=2, baudrate=1_000_000, **bus_options)


@dataclass(frozen=True)
class EmulatorConfig:
    """Everything needed to build a virtual bus, e.g. from CLI options.

    Attributes:
        spec: models and ids (``"XL-320:1-6"``).
        protocol: None to take the models' protocol.
        baudrate: motors' baud rate and default line speed.
        wire_timing: delay replies like a real line.
        latency_s: adapter latency.
        adapter: ``"u2d2"`` or ``"usb2ax"``.
        seed: fault injection seed.
        options: any other :class:`VirtualBus` keyword.
    """

    spec: str
    protocol: int | None = None
    baudrate: int = 1_000_000
    wire_timing: bool = False
    latency_s: float = 0.0
    adapter: Adapter = "u2d2"
    seed: int = 0
    options: dict[str, Any] = field(default_factory=dict)

    def build(self) -> VirtualBus:
        """Build the :class:`VirtualBus` this config describes."""
        return build_bus_from_spec(
            self.spec,
            protocol=self.protocol,
            baudrate=self.baudrate,
            wire_timing=self.wire_timing,
            latency_s=self.latency_s,
            adapter=self.adapter,
            seed=self.seed,
            **self.options,
        )
