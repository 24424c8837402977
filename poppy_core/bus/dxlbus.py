"""``DxlBus``: thread-safe Dynamixel transactions (see ``poppy_core.bus.core`` for the engine).

Every method takes the bus lock for its whole transaction, waits as long as the wire physically
needs (``poppy_core.bus.timing``), retries timeouts and corrupt replies, and raises
``MotorError`` for refused instructions (alarm bits are logged, not raised; see ``core``).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from typing import Any

from poppy_core.bus import groupread
from poppy_core.bus.core import BusCore
from poppy_core.bus.results import PingResult
from poppy_core.bus.serial_line import AbsentLine
from poppy_core.bus.timing import reply_floor_s
from poppy_core.bus.transport import Transport
from poppy_core.errors import (
    BusTimeout,
    CorruptPacketError,
    PortError,
    ProtocolError,
    RegisterError,
)
from poppy_core.models import ServoModel, model_by_number
from poppy_core.protocol import BROADCAST_ID, InstructionPacket
from poppy_core.protocol import instructions as ins

logger = logging.getLogger(__name__)

# e-manual (AX-12A, MX-28 protocol 1 control tables): Model Number at 0 (2 bytes), Firmware
# Version at 2 (1 byte). Protocol 1 ping carries neither, so they are read after it.
V1_MODEL_NUMBER_ADDRESS = 0
V1_MODEL_INFO_LENGTH = 3


class DxlBus(BusCore):
    """One Dynamixel bus: a port, a baud rate, a protocol, one lock for every transaction.

    ``DxlBus(port, baudrate=1_000_000, protocol=1, *, latency_s=None, retries=1,
    return_delay_s=0.0005, sync_read=None, transport=None)``; see ``BusCore.__init__``.
    """

    def __enter__(self) -> DxlBus:
        return self

    @classmethod
    def absent(
        cls, port: str, baudrate: int, protocol: int, reason: PortError, **options: Any
    ) -> DxlBus:
        """A bus whose port is not there yet (``reason`` says why it could not be opened): every
        transaction raises ``PortError`` until ``reopen`` opens the port (a robot served at boot
        before its adapter or its power is there).

        Args:
            port: the device path or URL.
            baudrate: line speed in bit/s.
            protocol: Dynamixel protocol, 1 or 2.
            reason: the error opening the port raised.
            **options: the other arguments of ``DxlBus``.
        """
        line = AbsentLine(port, baudrate, reason)
        bus = cls(
            port,
            baudrate,
            protocol,
            transport=Transport(port, baudrate, protocol, line=line),
            **options,
        )
        bus.adopt_transport()
        return bus

    # -- single-motor transactions ------------------------------------------------------------

    def ping(
        self, id: int, *, retries: int | None = None, identify: bool = True
    ) -> PingResult | None:
        """Ping motor ``id``; None when nothing answers.

        Protocol 1 pings carry no model number: it and the firmware are read right after.

        Args:
            id: motor ID (0-253).
            retries: extra attempts (None: the bus's ``retries``).
            identify: read the protocol 1 model number; False only checks that it answers
                (the result then has no model).

        Raises:
            CorruptPacketError: only garbage came back on every attempt.
        """
        proto = self._proto
        with self._lock:
            try:
                status = self._transact(ins.ping(id), id, proto.ping_params, retries=retries)
            except BusTimeout:
                return None
            self.record_alarms(status)
            identity = proto.ping_identity(status.params)
            if identity is not None:
                number, firmware = identity
                return PingResult(id, number, firmware, model_by_number(number))
            if not identify:
                return PingResult(id, None, None, None)
            try:
                info = self._read_model_info(id)
            except (BusTimeout, CorruptPacketError) as exc:
                logger.warning("motor %d answered a ping but not a read: %s", id, exc)
                return PingResult(id, None, None, None)
        number = int.from_bytes(info[:2], "little")
        return PingResult(id, number, info[2], model_by_number(number))

    def _read_model_info(self, id: int) -> bytes:
        """Protocol 1 model number and firmware of a motor that just answered a ping.

        The motor is known to be there: its reply gets the usual floor and at least one retry,
        whatever the ping had (a scan pings with no retry and no floor).
        """
        packet = ins.read(self._protocol, id, V1_MODEL_NUMBER_ADDRESS, V1_MODEL_INFO_LENGTH)
        floor = max(self.min_timeout_s, reply_floor_s())
        status = self._transact(
            packet, id, V1_MODEL_INFO_LENGTH, retries=max(1, self.retries), min_timeout_s=floor
        )
        self.check_status(status)
        return status.params

    def read(self, id: int, address: int, length: int) -> bytes:
        """Read ``length`` bytes at ``address`` of motor ``id``.

        Raises:
            BusTimeout, CorruptPacketError: no valid reply after the retries.
            MotorError: the motor refused the read.
        """
        status = self._transact(ins.read(self._protocol, id, address, length), id, length)
        self.check_status(status)
        return status.params

    def write(self, id: int, address: int, data: bytes, *, reply: bool = True) -> None:
        """Write ``data`` at ``address`` of motor ``id``.

        Args:
            id: motor ID, or ``BROADCAST_ID`` (never answers).
            address: first control table address.
            data: the bytes.
            reply: wait for the status packet (False when the status return level is low).
        """
        self._write(ins.write(self._protocol, id, address, data), id, reply)

    def reg_write(self, id: int, address: int, data: bytes, *, reply: bool = True) -> None:
        """Register a write that the motor performs at the next ``action``."""
        self._write(ins.reg_write(self._protocol, id, address, data), id, reply)

    def _write(self, packet: InstructionPacket, id: int, reply: bool) -> None:
        if not reply or id == BROADCAST_ID:
            self._send(packet)
            return
        self.check_status(self._transact(packet, id, 0))

    def action(self, id: int = BROADCAST_ID, *, reply: bool = True) -> None:
        """Trigger the registered writes (broadcast by default, which never answers)."""
        self._write(ins.action(id), id, reply)

    def reboot(self, id: int) -> None:
        """Reboot motor ``id`` (protocol 2); returns once the motor acknowledged."""
        self._need(self._proto.has_reboot, "reboot")
        self._write(ins.reboot(id), id, True)

    def clear(self, id: int) -> None:
        """Clear the multi-turn revolution count of motor ``id`` (protocol 2)."""
        self._need(self._proto.has_clear, "clear")
        self._write(ins.clear(id), id, True)

    def factory_reset(self, id: int, option: int | None = None) -> None:
        """Reset motor ``id`` to factory settings.

        Args:
            id: motor ID.
            option: protocol 2 only: 0xFF all, 0x01 all but ID, 0x02 all but ID and baud rate.
                None resets everything (protocol 1 always does).
        """
        packet = (
            ins.factory_reset(self._protocol, id)
            if option is None
            else ins.factory_reset(self._protocol, id, option)
        )
        self._write(packet, id, True)

    def _need(self, capability: bool, what: str) -> None:
        """Refuse ``what`` on a protocol without it (only protocol 1 lacks any of them)."""
        if not capability:
            raise ProtocolError(
                f"{what} exists only in protocol 2 (bus {self._port} is protocol {self._protocol})"
            )

    # -- registers in SI units -----------------------------------------------------------------

    def read_register(self, id: int, model: ServoModel, name: str) -> float | int | bool | str:
        """Read register ``name`` of motor ``id`` and convert it to SI units.

        Raises:
            RegisterError: unknown register for this model.
        """
        register = model.register(name)
        data = self.read(id, register.address, register.size)
        return register.decode_si(data)

    def write_register(
        self, id: int, model: ServoModel, name: str, value: float | int | bool | str
    ) -> None:
        """Convert ``value`` from SI units and write it to register ``name`` of motor ``id``.

        Raises:
            RegisterError: unknown or read-only register, value out of range.
        """
        register = model.register(name)
        if not register.writable:
            raise RegisterError(f"{register.name} is read-only", register=register.name)
        raw = register.from_si(value)
        self.write(id, register.address, register.encode(raw))

    # -- several motors ----------------------------------------------------------------------------

    def sync_read(self, address: int, length: int, ids: Sequence[int]) -> dict[int, bytes | None]:
        """Read the same ``length`` bytes at ``address`` of several motors.

        Protocol 2 uses SYNC_READ; protocol 1 the USB2AX sync read when the adapter has it, else
        BULK_READ (MX) or one read per motor. The method that works is found once and kept
        (``sync_read_mode``). A motor that does not answer maps to None.

        Raises:
            MotorError: a motor refused the read.
        """
        return groupread.sync_read(self, address, length, list(ids))

    def fast_sync_read(
        self, address: int, length: int, ids: Sequence[int]
    ) -> dict[int, bytes | None]:
        """Protocol 2 FAST_SYNC_READ: one combined reply for every motor."""
        self._need(self._proto.has_fast_sync_read, "fast sync read")
        return groupread.fast_sync_read(self, address, length, list(ids))

    def bulk_read(self, requests: Sequence[tuple[int, int, int]]) -> dict[int, bytes | None]:
        """Read ``(id, address, length)`` for several motors in one instruction (BULK_READ).

        Motors that miss the bulk read (e.g. protocol 1 AX servos, which lack it) are read one
        by one. A motor that still does not answer maps to None.
        """
        return groupread.bulk_read(self, list(requests))

    def sync_write(self, address: int, data: Mapping[int, bytes]) -> None:
        """Write the same-sized ``data[id]`` at ``address`` of several motors (no reply)."""
        if not data:
            return
        length = len(next(iter(data.values())))
        self._send(ins.sync_write(self._protocol, address, length, data))

    def bulk_write(self, requests: Sequence[tuple[int, int, bytes]]) -> None:
        """Write ``(id, address, data)`` to several motors in one instruction (protocol 2)."""
        self._need(self._proto.has_bulk_write, "bulk write")
        if requests:
            self._send(ins.bulk_write(requests))

    def broadcast_ping(self) -> list[PingResult]:
        """Ping every motor at once (protocol 2); collects replies until the line is quiet."""
        self._need(self._proto.has_broadcast_ping, "broadcast ping")
        return groupread.broadcast_ping(self)
