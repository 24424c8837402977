"""Multi-motor reads of ``DxlBus``: sync, USB2AX sync, bulk, fast sync read, broadcast ping.

Protocol 1 sync read strategy (found once per bus, kept in ``bus.sync_read_mode``):

1. the USB2AX sync read (0x84): the adapter answers with one packet from ID 0xFD. No answer at
   all means the adapter lacks it (``bus.usb2ax = False``) and it is not tried again;
2. else BULK_READ (MX servos have it, AX servos ignore it);
3. else one READ per motor (``"sequential"``) when motors that missed the bulk read answer a
   plain read.

The USB2AX fills a motor that did not answer with 0xFF bytes: an all-0xFF block maps to None.

A motor missing from a group reply once its retries are spent (a corrupt byte in a long reply,
a reply chain cut by a silent motor) is read on its own before it is reported as None: a long
reply is many times likelier to be hit by noise than a short one, and a healthy motor must not
look silent because a neighbour's reply was garbled. A transient failure never changes the
method found for the bus.
"""

from __future__ import annotations

import logging
from collections import Counter
from collections.abc import Callable
from typing import TYPE_CHECKING

from poppy_core.bus.replies import is_alarm_only, reply_fits
from poppy_core.bus.results import PingResult
from poppy_core.bus.timing import Deadline, settle_s, status_size
from poppy_core.errors import BusTimeout, CorruptPacketError
from poppy_core.models import model_by_number
from poppy_core.protocol import (
    BROADCAST_ID,
    USB2AX_ID,
    InstructionPacket,
    StatusPacket,
    encode_instruction,
    parse_fast_sync_status,
    parse_usb2ax_sync_status,
)
from poppy_core.protocol import instructions as ins

if TYPE_CHECKING:
    from poppy_core.bus.dxlbus import DxlBus

logger = logging.getLogger(__name__)

# The USB2AX reads each motor itself; allow this much per motor on top of the wire time for its
# firmware and for a motor that does not answer (USB2AX firmware waits about a millisecond).
USB2AX_PER_MOTOR_S = 0.0015


def exchange_with_retries(
    bus: DxlBus,
    make_packet: Callable[[list[int]], InstructionPacket],
    expected: dict[int, int],
    *,
    timeout_s: Callable[[list[int]], float] | None = None,
    retries: int | None = None,
) -> dict[int, StatusPacket]:
    """Run a multi-reply instruction, asking again only the motors that did not answer.

    Args:
        bus: the bus (its lock is taken).
        make_packet: builds the instruction for a list of motor IDs.
        expected: motor ID -> number of parameter bytes of its reply, in reply order.
        timeout_s: optional first-reply timeout for a list of motor IDs.
        retries: extra attempts (None: the bus's ``retries``).

    Returns:
        The usable replies, by ID (missing motors are absent).
    """
    got: dict[int, StatusPacket] = {}
    missing = list(expected)
    with bus.lock:
        bus.stats.transactions += 1
        for attempt in range(1 + (bus.retries if retries is None else retries)):
            if attempt:
                bus.stats.retries += 1
            replies = bus.exchange(
                make_packet(missing),
                [(i, expected[i]) for i in missing],
                timeout_s=None if timeout_s is None else timeout_s(missing),
            )
            for motor_id, status in replies.items():
                if reply_fits(bus.protocol, status, expected[motor_id]):
                    got[motor_id] = status
                else:
                    bus.stats.corrupt_packets += 1
            missing = [i for i in missing if i not in got]
            if not missing:
                break
            # Motors answer in a chain (each after the previous one): a silent motor silences
            # every motor after it. Ask it last next time so the others get through.
            missing = missing[1:] + missing[:1]
    return got


def _checked(
    bus: DxlBus, replies: dict[int, StatusPacket], ids: list[int]
) -> dict[int, bytes | None]:
    out: dict[int, bytes | None] = {}
    for motor_id in ids:
        status = replies.get(motor_id)
        if status is not None:
            bus.check_status(status)
        out[motor_id] = None if status is None else status.params
    return out


def _sequential(bus: DxlBus, requests: list[tuple[int, int, int]]) -> dict[int, bytes | None]:
    out: dict[int, bytes | None] = {}
    for motor_id, address, length in requests:
        try:
            out[motor_id] = bus.read(motor_id, address, length)
        except (BusTimeout, CorruptPacketError):
            out[motor_id] = None
    return out


def _fill_in(
    bus: DxlBus, result: dict[int, bytes | None], address: int, length: int
) -> dict[int, bytes | None]:
    """Read on its own each motor a group read left without data (see the module doc)."""
    missing = [(i, address, length) for i, data in result.items() if data is None]
    if missing:
        result.update(_sequential(bus, missing))
    return result


def _usb2ax(
    bus: DxlBus, address: int, length: int, ids: list[int], *, retries: int | None = None
) -> dict[int, bytes | None] | None:
    """USB2AX sync read; None when the adapter does not answer (it lacks the instruction)."""
    n_params = length * len(ids)
    timing = bus.timing
    # The adapter reads each motor (READ: 8 bytes out, status of 6 + length back), then answers.
    per_motor = timing.wire_s(8 + status_size(1, length)) + timing.return_delay_s
    timeout = timing.reply_timeout_s(
        len(encode_instruction(1, ins.sync_read(1, address, length, ids))), status_size(1, n_params)
    ) + len(ids) * (per_motor + USB2AX_PER_MOTOR_S)
    replies = exchange_with_retries(
        bus,
        lambda _missing: ins.sync_read(1, address, length, ids),
        {USB2AX_ID: n_params},
        timeout_s=lambda _missing: timeout,
        retries=retries,
    )
    status = replies.get(USB2AX_ID)
    if status is None:
        return None
    if bus.usb2ax and status.error and not is_alarm_only(1, status.error):
        # The adapter reads the motors itself and answers for them: an error in its own
        # status is noise that passed the 8-bit checksum. Read again as for a garbled reply.
        logger.debug("%s: USB2AX status with error bits %#04x, read again", bus.port, status.error)
        return None
    bus.check_status(status)
    blocks = parse_usb2ax_sync_status(status, length, ids)
    return {i: (None if all(b == 0xFF for b in data) else data) for i, data in blocks.items()}


def _usb2ax_in_halves(
    bus: DxlBus, address: int, length: int, ids: list[int]
) -> dict[int, bytes | None]:
    """USB2AX sync reads of each half of ``ids``, each half split again if its reply is garbled.

    After a whole-group reply came garbled: on a noisy line a long reply is seldom clean and a
    short one mostly is, while each reply costs a round trip. Halving finds the balance; a
    single motor left is read the plain way (see ``_fill_in``).
    """
    if len(ids) <= 1:
        return dict.fromkeys(ids)
    out: dict[int, bytes | None] = {}
    middle = (len(ids) + 1) // 2
    for half in (ids[:middle], ids[middle:]):
        data = _usb2ax(bus, address, length, half, retries=0)
        out.update(data if data is not None else _usb2ax_in_halves(bus, address, length, half))
    return out


def _bulk(bus: DxlBus, requests: list[tuple[int, int, int]]) -> dict[int, StatusPacket]:
    by_id = {r[0]: r for r in requests}
    return exchange_with_retries(
        bus,
        lambda missing: ins.bulk_read(bus.protocol, [by_id[i] for i in missing]),
        {r[0]: r[2] for r in requests},
    )


def sync_read(bus: DxlBus, address: int, length: int, ids: list[int]) -> dict[int, bytes | None]:
    """``DxlBus.sync_read`` (see the module docstring for the protocol 1 strategy)."""
    if not ids:
        return {}
    requests = [(i, address, length) for i in ids]
    with bus.lock:
        if bus.proto.has_sync_read:
            if bus.sync_read_enabled is False:
                bus.sync_read_mode = "bulk"
                return _checked(bus, _bulk(bus, requests), ids)
            bus.sync_read_mode = "sync"
            replies = exchange_with_retries(
                bus,
                lambda missing: ins.sync_read(2, address, length, missing),
                dict.fromkeys(ids, length),
            )
            return _fill_in(bus, _checked(bus, replies, ids), address, length)
        mode = bus.sync_read_mode
        try_usb2ax = bus.sync_read_enabled is not False and bus.usb2ax is not False
        if mode == "sync" or (mode is None and try_usb2ax):
            # Once the adapter is known to answer, one try for the whole group: if its reply
            # is garbled, smaller groups get through sooner than the same long one again.
            data = _usb2ax(bus, address, length, ids, retries=0 if bus.usb2ax else None)
            if data is not None:
                bus.usb2ax = True
                bus.sync_read_mode = "sync"
                return _fill_in(bus, data, address, length)
            if bus.usb2ax or bus.sync_read_enabled is True:
                # The adapter answered before (or must): this reply was lost or garbled.
                data = _usb2ax_in_halves(bus, address, length, ids)
                return _fill_in(bus, data, address, length)
            logger.info("%s: no USB2AX sync read; trying bulk read", bus.port)
            bus.usb2ax = False
            bus.sync_read_mode = mode = None
        if mode == "sequential":
            return _sequential(bus, requests)
        got = _bulk(bus, requests)
        result = _checked(bus, got, ids)
        missing = [r for r in requests if r[0] not in got]
        if mode == "bulk" or not missing:
            if got:
                bus.sync_read_mode = "bulk"
            return _fill_in(bus, result, address, length)
        rest = _sequential(bus, missing)
        result.update(rest)
        if any(value is not None for value in rest.values()):
            logger.info("%s: bulk read not supported by every motor; reading one by one", bus.port)
            bus.sync_read_mode = "sequential"
        elif got:
            bus.sync_read_mode = "bulk"
        return result


def bulk_read(bus: DxlBus, requests: list[tuple[int, int, int]]) -> dict[int, bytes | None]:
    """``DxlBus.bulk_read``: BULK_READ, then plain reads for the motors that missed it."""
    if not requests:
        return {}
    ids = [r[0] for r in requests]
    with bus.lock:
        got = _bulk(bus, requests)
        result = _checked(bus, got, ids)
        missing = [r for r in requests if r[0] not in got]
        if missing:
            result.update(_sequential(bus, missing))
    return result


def fast_sync_read(
    bus: DxlBus, address: int, length: int, ids: list[int]
) -> dict[int, bytes | None]:
    """``DxlBus.fast_sync_read``: one combined status packet from the broadcast ID."""
    if not ids:
        return {}
    n_params = len(ids) * (length + 4) - 3
    packet = ins.fast_sync_read(address, length, ids)
    timing = bus.timing
    timeout = (
        timing.reply_timeout_s(len(encode_instruction(2, packet)), status_size(2, n_params))
        + len(ids) * timing.return_delay_s
    )
    replies = exchange_with_retries(
        bus, lambda _missing: packet, {BROADCAST_ID: n_params}, timeout_s=lambda _m: timeout
    )
    status = replies.get(BROADCAST_ID)
    if status is None:
        # A silent motor cuts the combined reply short: read the motors the usual way instead.
        logger.debug("%s: no complete fast sync read reply; using sync read", bus.port)
        return sync_read(bus, address, length, ids)
    blocks = parse_fast_sync_status(status, length)
    out: dict[int, bytes | None] = {}
    for motor_id in ids:
        block = blocks.get(motor_id)
        if block is None:
            out[motor_id] = None
            continue
        bus.check_status(StatusPacket(motor_id, block[0], block[1]))
        out[motor_id] = block[1]
    return out


def broadcast_ping(bus: DxlBus) -> list[PingResult]:
    """``DxlBus.broadcast_ping``: collect every reply until the line has been quiet long enough.

    The first reply is awaited for one physical round trip, and at least the bus's
    ``min_timeout_s`` as every other transaction (a scan's bus has none); each reply then
    extends the wait by the time one more reply needs (return delay + its bytes + latency +
    margin): motors answer one after the other, so a silence that long means the last one has
    spoken. A second reply from the same ID counts as a corrupt packet.
    """
    found: dict[int, PingResult] = {}
    for result in broadcast_ping_replies(bus):
        if result.id in found:
            bus.stats.corrupt_packets += 1
            continue
        found[result.id] = result
    return [found[i] for i in sorted(found)]


def broadcast_ping_replies(bus: DxlBus) -> list[PingResult]:
    """Every reply to one broadcast ping (protocol 2), in the order heard, repeats included:
    two motors sharing an ID both answer (``poppy doctor`` tells duplicated IDs this way)."""
    timing = bus.timing
    size = status_size(2, 3)
    replies: list[PingResult] = []
    with bus.lock:
        bus.stats.transactions += 1
        transport = bus.transport
        bus.exchange(ins.ping(BROADCAST_ID), [])
        first = timing.reply_timeout_s(len(encode_instruction(2, ins.ping(BROADCAST_ID))), size)
        deadline = Deadline(max(first, bus.min_timeout_s))
        while True:
            status = transport.read_packet(deadline, grace_s=timing.grace_s(size))
            if status is None:
                break
            if len(status.params) != 3:
                bus.stats.corrupt_packets += 1
                continue
            bus.record_alarms(status)
            number = int.from_bytes(status.params[:2], "little")
            replies.append(PingResult(status.id, number, status.params[2], model_by_number(number)))
            deadline.extend(timing.quiet_gap_s(size))
    return replies


def count_answers(bus: DxlBus, late_s: float = 0.1) -> Counter[int]:
    """How many motors answer as each ID (protocol 2): one broadcast ping, then the line is
    listened to for ``late_s`` more (plus the adapter's settle time), so that replies still on
    their way count too and are not taken for the answers to what follows."""
    counts = Counter(reply.id for reply in broadcast_ping_replies(bus))
    late = bus.listen(settle_s(bus.latency_s) + late_s)
    counts.update(s.id for s in late if len(s.params) == bus.proto.ping_params)
    return counts
