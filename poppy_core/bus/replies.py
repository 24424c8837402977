"""Replies to one instruction: waiting for them, which to keep, what their error bits mean.

``BusCore.exchange`` sends the instruction and sets the deadline of the first reply;
``collect_replies`` reads the replies that come until each motor asked has answered, the
deadline has passed, or as many bytes as the replies came but some garbled (no point waiting out
the deadline: the retry goes out at once). A status that is not a reply asked for (another ID,
another size: a late answer to an earlier instruction) is set aside, not taken for one.

Error bits policy (``ErrorBits``, relied upon above):

* *Alarm* bits report the motor's state, not a refused instruction: protocol 1 input voltage,
  overheating and overload; protocol 2 the hardware alert bit (bit 7) with no error number. The
  instruction was executed, so the data is returned (or the write counted as done); the alarm is
  logged once when it appears, counted in ``stats.alarms`` and kept in ``bus.alarms[id]``.
* Any other bit (protocol 1 angle limit, range, checksum, instruction; protocol 2 error numbers)
  means the instruction was refused: ``MotorError`` is raised, naming the motor and the bits.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Sequence

from poppy_core.bus.results import BusStats
from poppy_core.bus.timing import Deadline, LinkTiming
from poppy_core.bus.transport import Transport
from poppy_core.errors import MotorError
from poppy_core.protocol import DxlProtocol, StatusPacket, protocol_for

logger = logging.getLogger(__name__)


def is_alarm_only(protocol: int | DxlProtocol, error: int) -> bool:
    """True when ``error`` carries only alarm bits (the instruction was still executed)."""
    return protocol_for(protocol).is_alarm_only(error)


def reply_fits(protocol: int | DxlProtocol, status: StatusPacket, n_params: int) -> bool:
    """A reply to keep: ``n_params`` bytes of data, or a refusal (which carries none and is
    checked later).

    A status of another size is a late answer to an earlier instruction (for instance a write
    sent with ``reply=False`` that was answered all the same): it is kept aside.
    """
    if len(status.params) == n_params:
        return True
    return bool(status.error) and not is_alarm_only(protocol, status.error)


def collect_replies(
    transport: Transport,
    proto: DxlProtocol,
    expected: Sequence[tuple[int, int]],
    deadline: Deadline,
    timing: LinkTiming,
    stats: BusStats,
    *,
    observe: Callable[[StatusPacket, float], None],
    set_aside: Callable[[StatusPacket], None],
    port: str,
) -> dict[int, StatusPacket]:
    """The replies of the ``expected`` motors that come by ``deadline``, by ID.

    Args:
        transport: the transport the instruction was just written to.
        proto: the bus's protocol.
        expected: ``(id, n_params)`` of each reply, in the order motors send them.
        deadline: when to stop waiting for the first reply; each reply kept extends it by the
            line's quiet gap, and a reply that has started is not cut (``grace_s``).
        timing: the link's timing model.
        stats: counts the replies that did not come (``timeouts``) and came garbled
            (``corrupt_packets``).
        observe: called with each status and when it arrived (the bus times its replies).
        set_aside: takes each status that is not a reply asked for.
        port: the port's name, for the log.
    """
    corrupt_before, skipped_before = transport.corrupt_packets, transport.skipped_bytes
    sizes = [proto.status_size(n) for _, n in expected]
    grace = timing.grace_s(max(sizes))
    wanted = {motor_id for motor_id, _ in expected}
    sizes_by_id = dict(expected)
    got: dict[int, StatusPacket] = {}
    expected_bytes = sum(sizes)
    received_before = transport.bytes_received
    stray_bytes = 0

    def all_came() -> bool:
        """As many bytes as the replies came, some garbled: no point waiting out the
        deadline (the retry goes out at once)."""
        if len(got) + transport.corrupt_packets - corrupt_before >= len(wanted):
            return True
        return transport.bytes_received - received_before - stray_bytes >= expected_bytes

    while len(got) < len(wanted):
        status = transport.read_packet(deadline, grace_s=grace, give_up=all_came)
        if status is None:
            break
        observe(status, time.monotonic())
        if (
            status.id in wanted
            and status.id not in got
            and reply_fits(proto, status, sizes_by_id[status.id])
        ):
            got[status.id] = status
            deadline.extend(timing.quiet_gap_s(max(sizes)))
        else:
            logger.debug("%s: stray status from ID %d kept aside", port, status.id)
            set_aside(status)
            stray_bytes += proto.status_size(len(status.params))
    corrupt = transport.corrupt_packets - corrupt_before
    if len(got) < len(wanted) and not corrupt and transport.skipped_bytes > skipped_before:
        corrupt = 1  # bytes came back but no packet could be found in them: garbage
    stats.corrupt_packets += corrupt
    stats.timeouts += len(wanted) - len(got)
    return got


class ErrorBits:
    """The error-bits policy (module doc) of one bus: refusals raised, alarms kept and logged.

    Args:
        proto: the bus's protocol (it names the bits).
        port: the port's name, for messages.
        stats: counts the refusals (``motor_errors``) and the alarms.
    """

    def __init__(self, proto: DxlProtocol, port: str, stats: BusStats) -> None:
        self._proto = proto
        self._port = port
        self._stats = stats
        self.alarms: dict[int, list[str]] = {}
        """Motor ID -> alarm names from its last status packet (empty list once cleared)."""

    def check(self, status: StatusPacket, *, register: str | None = None) -> None:
        """Raise ``MotorError`` for refusal bits; log and record alarm bits."""
        if status.error == 0 or self._proto.is_alarm_only(status.error):
            self.record(status)
            return
        self._stats.motor_errors += 1
        names = self._proto.decode_errors(status.error)
        where = f" ({register})" if register else ""
        raise MotorError(
            f"motor {status.id} on {self._port}{where} reported: {', '.join(names)}",
            motor_id=status.id,
            errors=names,
            register=register,
            port=self._port,
        )

    def record(self, status: StatusPacket) -> None:
        """Keep the alarm bits of ``status`` in ``alarms`` and log when they change."""
        names = self._proto.decode_errors(status.error) if status.error else []
        if names != self.alarms.get(status.id, []):
            if names:
                logger.warning(
                    "motor %d on %s reports: %s", status.id, self._port, ", ".join(names)
                )
            else:
                logger.info("motor %d on %s: alarm cleared", status.id, self._port)
        if names:
            self._stats.alarms += 1
        self.alarms[status.id] = names
