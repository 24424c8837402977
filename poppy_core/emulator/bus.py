"""VirtualBus: a half-duplex Dynamixel line with virtual motors, an adapter and a plant on it."""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

from poppy_core.emulator.dispatch import ReplyFrame, dispatch
from poppy_core.emulator.faults import FaultInjector
from poppy_core.emulator.linespeed import baud_matches
from poppy_core.emulator.motor import VirtualMotor
from poppy_core.emulator.plant import IdealPlant, Plant
from poppy_core.emulator.sniff import CorruptSniffer
from poppy_core.emulator.wire_timing import LineClock, transfer_time_s
from poppy_core.errors import ConfigError
from poppy_core.protocol import InstructionPacket, PacketDecoder, protocol_for

if TYPE_CHECKING:
    from poppy_core.emulator.hand import Hand

logger = logging.getLogger(__name__)

Adapter = Literal["u2d2", "usb2ax"]
ADAPTERS: tuple[str, ...] = ("u2d2", "usb2ax")


@dataclass(frozen=True)
class Reply:
    """Bytes to send back to the host, and when (``time.perf_counter`` clock; 0 = now)."""

    data: bytes
    send_at: float = 0.0


class VirtualBus:
    """Virtual motors on one line: takes instruction bytes, gives back status bytes.

    Args:
        motors: the motors on the line.
        protocol: 1 or 2; every motor's model must speak it.
        baudrate: line speed used when the transport has none (TCP, direct calls).
        wire_timing: delay replies as a real line would (see ``Reply.send_at``).
        latency_s: adapter/USB latency added to every reply.
        plant: what moves the horns; None gives an :class:`IdealPlant`.
        adapter: ``"u2d2"`` or ``"usb2ax"`` (the USB2AX also answers the protocol 1 sync
            read 0x84 and a PING to its own id 0xFD).
        seed: seed of the fault injector's random generator.
        faults: a fault injector to share; None creates one seeded with ``seed``.
        auto_step: step the plant by the elapsed time before each instruction; False leaves
            the plant still until :meth:`advance` is called with a duration (deterministic).
        clock: monotonic clock in seconds used for the plant.

    Raises:
        ConfigError: bad protocol, adapter or a motor of the other protocol.
    """

    def __init__(
        self,
        motors: Iterable[VirtualMotor],
        protocol: int,
        baudrate: int = 1_000_000,
        *,
        wire_timing: bool = False,
        latency_s: float = 0.0,
        plant: Plant | None = None,
        adapter: Adapter = "u2d2",
        seed: int = 0,
        faults: FaultInjector | None = None,
        auto_step: bool = True,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        if protocol not in (1, 2):
            raise ConfigError(f"unknown protocol {protocol!r}", field="protocol", value=protocol)
        if adapter not in ADAPTERS:
            raise ConfigError(
                f"unknown adapter {adapter!r} (expected one of {', '.join(ADAPTERS)})",
                field="adapter",
                value=adapter,
            )
        self._motors = list(motors)
        self._detached: set[int] = set()  # places (1-based) of motors taken off the line
        for motor in self._motors:
            if motor.protocol != protocol:
                raise ConfigError(
                    f"{motor.model.name} speaks protocol {motor.protocol}, "
                    f"the bus protocol {protocol}",
                    field="protocol",
                    value=protocol,
                )
        self.protocol = protocol
        self.proto = protocol_for(protocol)
        self.baudrate = baudrate
        self.wire_timing = wire_timing
        self.latency_s = latency_s
        self.adapter: Adapter = adapter
        self.faults = faults if faults is not None else FaultInjector(seed)
        self.auto_step = auto_step
        self._clock = clock
        self._lock = threading.RLock()
        for motor in self._motors:
            motor.lock = self._lock
        self.plant: Plant = plant if plant is not None else IdealPlant()
        self.plant.attach(self._motors)
        self._last_step = clock()
        self._decoder = PacketDecoder(self.proto, "instruction")
        self._sniffer = CorruptSniffer(self.proto)
        self._line = LineClock()
        self.packets_received = 0
        self._hand: Hand | None = None

    # ------------------------------------------------------------------ motors and knobs

    @property
    def motors(self) -> list[VirtualMotor]:
        """The motors on the line (plugged or not), in the order given."""
        return list(self._motors)

    def motor(self, motor_id: int) -> VirtualMotor:
        """The motor whose control table currently holds ``motor_id``.

        Raises:
            KeyError: no motor has that id.
        """
        for motor in self._motors:
            if motor.id == motor_id:
                return motor
        raise KeyError(f"no virtual motor with id {motor_id}")

    def unplug(self, motor_id: int) -> None:
        """Disconnect motor ``motor_id``: silence until :meth:`plug`."""
        self.faults.unplug(motor_id)

    def plug(self, motor_id: int) -> None:
        """Reconnect motor ``motor_id``."""
        self.faults.plug(motor_id)

    def _place(self, place: int) -> int:
        if not 1 <= place <= len(self._motors):
            raise KeyError(f"no motor at place {place} (places 1-{len(self._motors)})")
        return place

    def detach(self, place: int) -> None:
        """Take the motor at ``place`` (1-based, in the order given) off the line, whatever its
        ID: a motor in its box. Motors sharing an ID (a kit, all at the factory ID 1) are told
        apart this way.

        Raises:
            KeyError: no motor at that place.
        """
        with self._lock:
            self._detached.add(self._place(place))

    def attach(self, place: int) -> None:
        """Put the motor at ``place`` back on the line (see :meth:`detach`).

        Raises:
            KeyError: no motor at that place.
        """
        with self._lock:
            self._detached.discard(self._place(place))

    def is_attached(self, place: int) -> bool:
        """Whether the motor at ``place`` (1-based) is on the line."""
        return self._place(place) not in self._detached

    @property
    def corrupt_rate(self) -> float:
        """Probability that a reply byte gets a bit flipped."""
        return self.faults.corrupt_rate

    @corrupt_rate.setter
    def corrupt_rate(self, value: float) -> None:
        self.faults.corrupt_rate = value

    @property
    def drop_rate(self) -> float:
        """Probability that a reply is lost."""
        return self.faults.drop_rate

    @drop_rate.setter
    def drop_rate(self, value: float) -> None:
        self.faults.drop_rate = value

    @property
    def extra_delay_s(self) -> float:
        """Delay added to every reply."""
        return self.faults.extra_delay_s

    @extra_delay_s.setter
    def extra_delay_s(self, value: float) -> None:
        self.faults.extra_delay_s = value

    @property
    def corrupt_packets(self) -> int:
        """Instruction packets received with a bad checksum/CRC or shape."""
        return self._decoder.corrupt_packets

    def hears(self, motor: VirtualMotor, line_bps: int) -> bool:
        """Whether ``motor`` is on the line, plugged, and its UART decodes bytes sent at
        ``line_bps``."""
        if self._detached and self._motors.index(motor) + 1 in self._detached:
            return False
        return not self.faults.is_unplugged(motor.id) and baud_matches(line_bps, motor.baudrate_bps)

    # ------------------------------------------------------------------ plant

    @property
    def hand(self) -> Hand:
        """A hand on this bus's motors (made at first use; see ``poppy_core.emulator.hand``)."""
        with self._lock:
            if self._hand is None:
                from poppy_core.emulator.hand import Hand

                self._hand = Hand(self)
            return self._hand

    def advance(self, dt_s: float | None = None) -> None:
        """Step the plant: by ``dt_s`` seconds, or by the time elapsed since the last step."""
        with self._lock:
            now = self._clock()
            if dt_s is None:
                dt_s = now - self._last_step if self.auto_step else 0.0
            self._last_step = now
            if dt_s > 0:
                self.plant.step(dt_s)

    # ------------------------------------------------------------------ bytes in, bytes out

    def reset_input(self) -> None:
        """Drop partial instruction bytes and line history (a new client connected)."""
        with self._lock:
            self._decoder.reset()
            self._sniffer.reset()
            self._line.reset()

    def receive(
        self, data: bytes, *, line_bps: int | None = None, received_at: float | None = None
    ) -> list[Reply]:
        """Handle instruction bytes as they arrive on the line.

        Args:
            data: bytes from the host, in any split.
            line_bps: rate the host sends at (a pty's termios); None uses ``baudrate``.
            received_at: ``time.perf_counter()`` when the bytes were read (default: now).

        Returns:
            The replies, in order, each with the time it is due.
        """
        line = line_bps or self.baudrate
        now = time.perf_counter()
        with self._lock:
            arrival = self._line.receive(len(data), received_at or now, line)
            before = self._decoder.corrupt_packets
            self._sniffer.feed(data)
            packets = self._decoder.feed(data)
            corrupt = self._decoder.corrupt_packets - before
            if not packets and not corrupt:
                return []
            if self.auto_step:
                self.advance()
            frames: list[ReplyFrame] = []
            if corrupt:
                frames += self._checksum_replies(corrupt, line)
            for packet in packets:
                if isinstance(packet, InstructionPacket):
                    self.packets_received += 1
                    frames += dispatch(self, packet, line)
            return self._schedule(frames, arrival, line, now)

    def process(self, data: bytes, *, line_bps: int | None = None) -> bytes:
        """Handle instruction bytes and return every reply at once (no waiting)."""
        return b"".join(reply.data for reply in self.receive(data, line_bps=line_bps))

    def _checksum_replies(self, count: int, line: int) -> list[ReplyFrame]:
        frames: list[ReplyFrame] = []
        for packet_id, instruction in self._sniffer.corrupt_frames(count):
            for motor in self._motors:
                if motor.id == packet_id and self.hears(motor, line):
                    status = motor.checksum_error(instruction)
                    if status is not None:
                        frames.append(ReplyFrame.status(self.protocol, motor, status))
        return frames

    def _schedule(
        self, frames: list[ReplyFrame], arrival: float, line: int, now: float
    ) -> list[Reply]:
        """Put replies on the line one after the other and apply the fault knobs."""
        replies: list[Reply] = []
        t = arrival
        for frame in frames:
            t += frame.delay_s
            if frame.on_wire:
                t += transfer_time_s(len(frame.data), line)
            data = self.faults.filter_reply(frame.data)
            if data is None:
                continue
            extra = self.latency_s + self.faults.extra_delay_s
            if self.wire_timing:
                replies.append(Reply(data, t + extra))
            else:
                replies.append(Reply(data, now + extra if extra > 0 else 0.0))
        if self.wire_timing:
            self._line.occupy_until(t)
        return replies
