"""The transaction engine under ``DxlBus``: lock, physical deadlines, retries, error bits, counters.

One instruction is one ``exchange``: the bus sends it and sets the first reply's deadline, and
``poppy_core.bus.replies`` collects the replies. Error bits follow the policy written there
(``ErrorBits``: a refusal raises ``MotorError``, an alarm is recorded in ``bus.alarms``); ``ping``
never raises ``MotorError``: any valid reply proves the motor is there.

Retries: a timeout or a corrupt reply is retried ``retries`` times (``MotorError`` never is).
"""

from __future__ import annotations

import contextlib
import logging
import threading
import time
from collections import deque
from collections.abc import Iterator, Sequence

from poppy_core.bus.latency import ReplyClock
from poppy_core.bus.replies import ErrorBits, collect_replies
from poppy_core.bus.results import BusStats
from poppy_core.bus.timing import (
    DEFAULT_RETURN_DELAY_S,
    Deadline,
    LinkTiming,
    default_latency_s,
    reply_floor_s,
)
from poppy_core.bus.transport import Transport
from poppy_core.errors import BusTimeout, CorruptPacketError, PortError, ProtocolError
from poppy_core.protocol import (
    BROADCAST_ID,
    DxlProtocol,
    Instruction,
    InstructionPacket,
    StatusPacket,
    protocol_for,
)

logger = logging.getLogger(__name__)


class BusCore:
    """One Dynamixel bus: a port, a baud rate, a protocol, and one lock for every transaction.

    Timeouts come from ``LinkTiming`` (baud rate, packet sizes, return delay, adapter latency);
    see ``poppy_core.bus.timing``. ``latency_s=None`` picks the adapter latency from the port
    (FTDI latency timer from sysfs, 2 ms for other devices, 1 ms for ptys and URLs).

    Attributes:
        retries: extra attempts after a timeout or a corrupt reply.
        stats: counters (``BusStats``).
        timeout_s: fixed reply timeout, None to compute it from the link timing.
        sync_read_enabled: the ``sync_read`` argument (True, False or None for auto).
        sync_read_mode: how ``sync_read`` reads: ``"sync"``, ``"bulk"``, ``"sequential"``, or
            None until found out.
        usb2ax: whether the adapter answers the USB2AX sync read (None until tried).
        alarms: motor ID -> alarm names from its last status packet (empty list once cleared).
        adaptive_latency: raise ``latency_s`` when a reply shows the adapter is slower than
            assumed (scans set it; see ``poppy_core.bus.latency``).
    """

    def __init__(
        self,
        port: str,
        baudrate: int = 1_000_000,
        protocol: int = 1,
        *,
        latency_s: float | None = None,
        retries: int = 1,
        return_delay_s: float = DEFAULT_RETURN_DELAY_S,
        sync_read: bool | None = None,
        transport: Transport | None = None,
        timeout_s: float | None = None,
        min_timeout_s: float | None = None,
    ) -> None:
        """Open a bus.

        Args:
            port: device path or pyserial URL (``socket://host:port``, ``loop://``).
            baudrate: line speed in bit/s.
            protocol: Dynamixel protocol, 1 or 2.
            latency_s: adapter latency; None picks it from the port (see above).
            retries: extra attempts after a timeout or a corrupt reply.
            return_delay_s: the motors' return delay assumed in timeouts (factory 500 µs).
            sync_read: use the sync read instruction (protocol 2 SYNC_READ, protocol 1 USB2AX
                0x84): True forces it, False never uses it, None tries it once and remembers.
            timeout_s: a fixed reply timeout replacing the physical estimate (for odd bridges;
                None, the default, computes it per transaction).
            min_timeout_s: the shortest wait for a first reply. A motor that is there answers
                long before it, so it only costs time when a reply is lost; it keeps a reply
                that the OS delivered late (a loaded machine, a busy emulator) from being taken
                for silence. Scans, which mostly wait for absent motors, pass 0. None: the
                real adapter's 10 ms, or ``$POPPY_REPLY_FLOOR_S`` (``timing.reply_floor_s``).
            transport: an open ``Transport`` to use instead of opening ``port``; the bus then
                sets its baud rate and protocol but does not close it.

        Raises:
            PortError: the port cannot be opened.
            ProtocolError: ``protocol`` is not 1 or 2.
            ConfigError: ``$POPPY_REPLY_FLOOR_S`` is not a number of seconds.
        """
        if protocol not in (1, 2):
            raise ProtocolError(f"protocol must be 1 or 2, not {protocol}")
        floor = reply_floor_s() if min_timeout_s is None else min_timeout_s
        self._protocol = protocol
        self._proto = protocol_for(protocol)
        self._owns_transport = transport is None
        if transport is None:
            transport = Transport(port, baudrate, protocol)
        else:
            transport.protocol = protocol
            if transport.baudrate != baudrate:
                transport.set_baudrate(baudrate)
        self._transport = transport
        self._port = port
        self._lock = threading.RLock()
        self._latency_s = default_latency_s(port) if latency_s is None else latency_s
        self._timing = LinkTiming(baudrate, return_delay_s, self._latency_s)
        self.retries = retries
        self.timeout_s = timeout_s
        self.min_timeout_s = floor
        self.stats = BusStats()
        self._errors = ErrorBits(self._proto, port, self.stats)
        self.alarms = self._errors.alarms
        self._strays: deque[StatusPacket] = deque(maxlen=256)
        self.sync_read_enabled = sync_read
        self.sync_read_mode: str | None = None
        self.usb2ax: bool | None = None
        self.adaptive_latency = False
        self._replies = ReplyClock()
        logger.debug(
            "bus %s: %d bps, protocol %d, latency %.1f ms",
            port,
            baudrate,
            protocol,
            self._latency_s * 1000,
        )

    # -- properties --------------------------------------------------------------------------

    @property
    def port(self) -> str:
        """The device path or URL."""
        return self._port

    @property
    def protocol(self) -> int:
        """Dynamixel protocol (1 or 2)."""
        return self._protocol

    @property
    def proto(self) -> DxlProtocol:
        """The protocol object: sizes, codec and capabilities (``poppy_core.protocol``)."""
        return self._proto

    @property
    def baudrate(self) -> int:
        """Line speed in bit/s; setting it reconfigures the port."""
        return self._timing.baudrate

    @baudrate.setter
    def baudrate(self, baudrate: int) -> None:
        with self._lock:
            self._transport.set_baudrate(baudrate)
            self._timing = LinkTiming(baudrate, self._timing.return_delay_s, self._latency_s)

    @property
    def latency_s(self) -> float:
        """Adapter latency assumed in timeouts; setting it changes the deadlines."""
        return self._latency_s

    @latency_s.setter
    def latency_s(self, latency_s: float) -> None:
        with self._lock:
            self._latency_s = latency_s
            self._timing = LinkTiming(self.baudrate, self._timing.return_delay_s, latency_s)

    def _observe(self, status: StatusPacket, at_s: float) -> None:
        """Time a reply against its instruction; a late one teaches a slower adapter.

        Only on an ``adaptive_latency`` bus, and only from a reply that came after its deadline
        (see ``poppy_core.bus.latency``).
        """
        if not self.adaptive_latency:
            return
        learned = self._replies.learn(status, at_s, self._timing, self._protocol)
        if learned is not None:
            self.latency_s = learned
            logger.info(
                "%s: a reply came late, the adapter is slower than assumed: waiting %.1f ms "
                "from now on",
                self._port,
                learned * 1000,
            )

    @property
    def timing(self) -> LinkTiming:
        """The timing model in use."""
        return self._timing

    @property
    def lock(self) -> threading.RLock:
        """The bus lock; hold it to chain several transactions without interleaving."""
        return self._lock

    @contextlib.contextmanager
    def patient(self, retries: int, min_timeout_s: float) -> Iterator[None]:
        """Transactions of the block (this thread holds the lock) try ``retries`` times more at
        least and wait ``min_timeout_s`` at least for a first reply.

        For a few one-off transactions with motors known to be there (a robot's start-up), where
        a reply the OS delivered late (a loaded machine, a starved emulator) must not count as
        silence; a motor answering in time costs nothing more.
        """
        with self._lock:
            saved = (self.retries, self.min_timeout_s)
            self.retries = max(retries, self.retries)
            self.min_timeout_s = max(min_timeout_s, self.min_timeout_s)
            try:
                yield
            finally:
                self.retries, self.min_timeout_s = saved

    # -- core ------------------------------------------------------------------------------------

    def exchange(
        self,
        packet: InstructionPacket,
        expected: Sequence[tuple[int, int]],
        *,
        timeout_s: float | None = None,
        min_timeout_s: float | None = None,
    ) -> dict[int, StatusPacket]:
        """Send one instruction and collect the replies of ``expected`` motors (one attempt).

        The caller should hold ``lock``. Replies from other IDs (late answers to an earlier
        instruction) are kept aside; ``take_strays`` returns them.

        Args:
            packet: the instruction.
            expected: ``(id, n_params)`` of each reply, in the order motors send them.
            timeout_s: wait for the first reply this long instead of the physical estimate.
            min_timeout_s: the shortest wait for the first reply (None: ``min_timeout_s``).

        Returns:
            The replies that arrived, by ID.
        """
        transport = self._transport
        drained_at = time.monotonic()
        for stray in transport.drain():
            self._observe(stray, drained_at)
            self._strays.append(stray)
        data = self._proto.encode_instruction(packet)
        transport.write(data)
        if packet.id != BROADCAST_ID:
            self._replies.sent(packet.id, time.monotonic(), len(data))
        elif self._proto.has_broadcast_ping and packet.instruction == Instruction.PING:
            self._replies.sent_to_all(time.monotonic(), len(data))
        if not expected:
            return {}
        first = timeout_s if timeout_s is not None else self.timeout_s
        if first is None:
            first = self._timing.reply_timeout_s(len(data), self._proto.status_size(expected[0][1]))
        floor = self.min_timeout_s if min_timeout_s is None else min_timeout_s
        return collect_replies(
            transport,
            self._proto,
            expected,
            Deadline(max(first, floor)),
            self._timing,
            self.stats,
            observe=self._observe,
            set_aside=self._strays.append,
            port=self._port,
        )

    def listen(self, duration_s: float) -> list[StatusPacket]:
        """Wait ``duration_s`` for late replies; return them with the strays kept aside.

        Each reply is timed as it arrives (an ``adaptive_latency`` bus learns from it).
        """
        with self._lock:
            late = list(self._strays)
            self._strays.clear()
            deadline = Deadline(duration_s)
            while (status := self._transport.read_packet(deadline)) is not None:
                self._observe(status, time.monotonic())
                late.append(status)
            return late

    def take_strays(self) -> list[StatusPacket]:
        """Return and forget the status packets that arrived for no pending transaction."""
        with self._lock:
            late = list(self._strays) + self._transport.drain()
            self._strays.clear()
            return late

    def _transact(
        self,
        packet: InstructionPacket,
        motor_id: int,
        n_params: int,
        *,
        retries: int | None = None,
        min_timeout_s: float | None = None,
    ) -> StatusPacket:
        """One instruction to one motor with retries; returns its checked-in reply."""
        attempts = 1 + (self.retries if retries is None else retries)
        corrupt = False
        with self._lock:
            self.stats.transactions += 1
            for attempt in range(attempts):
                if attempt:
                    self.stats.retries += 1
                before = self.stats.corrupt_packets
                expected = [(motor_id, n_params)]
                status = self.exchange(packet, expected, min_timeout_s=min_timeout_s).get(motor_id)
                if status is not None:
                    if status.error and not self._proto.is_alarm_only(status.error):
                        return status
                    if len(status.params) == n_params:
                        return status
                    self.stats.corrupt_packets += 1
                    corrupt = True
                    continue
                corrupt = self.stats.corrupt_packets > before
        what = f"instruction {packet.instruction:#04x}"
        if corrupt:
            raise CorruptPacketError(
                f"motor {motor_id} on {self._port} sent a corrupt reply to {what} "
                f"({attempts} attempt(s)); check wiring, baud rate and power",
                port=self._port,
                motor_id=motor_id,
            )
        raise BusTimeout(
            f"motor {motor_id} on {self._port} did not answer {what} at {self.baudrate} bps, "
            f"protocol {self._protocol} ({attempts} attempt(s))",
            port=self._port,
            motor_id=motor_id,
        )

    def check_status(self, status: StatusPacket, *, register: str | None = None) -> None:
        """Raise ``MotorError`` for refusal bits; log and record alarm bits (``ErrorBits``)."""
        self._errors.check(status, register=register)

    def record_alarms(self, status: StatusPacket) -> None:
        """Keep the alarm bits of ``status`` in ``alarms`` and log when they change."""
        self._errors.record(status)

    def _send(self, packet: InstructionPacket) -> None:
        with self._lock:
            self.stats.transactions += 1
            self.exchange(packet, [])

    # -- lifetime ----------------------------------------------------------------------------------

    @property
    def transport(self) -> Transport:
        """The underlying transport."""
        return self._transport

    def reopen(self) -> None:
        """Open the port again after it was lost (adapter re-plugged, emulator restarted).

        Counters, alarms and the sync read method found are kept.

        Raises:
            PortError: the port is still not there, or the bus was given its transport.
        """
        with self._lock:
            if not self._owns_transport:
                raise PortError(
                    f"{self._port}: the bus was given its transport, it cannot reopen it",
                    port=self._port,
                )
            with contextlib.suppress(Exception):  # a lost port may fail to close cleanly
                self._transport.close()
            self._transport = Transport(self._port, self.baudrate, self._protocol)
            self._strays.clear()
            self._replies.forget()

    @property
    def is_open(self) -> bool:
        """False while the port is closed (``close``, or a bus made ``absent``); ``reopen``
        opens it."""
        return self._transport.is_open

    def adopt_transport(self) -> None:
        """Close the transport it was given on ``close`` (a search hands on the port it opened)."""
        with self._lock:
            self._owns_transport = True

    def close(self) -> None:
        """Close the port (unless the transport was given by the caller). Idempotent."""
        with self._lock:
            if self._owns_transport:
                self._transport.close()

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"DxlBus({self._port!r}, baudrate={self.baudrate}, protocol={self._protocol})"
