"""Listening for late replies and asking again: how searches tell a motor from a slow echo."""

from __future__ import annotations

import logging

from poppy_core.bus.dxlbus import DxlBus
from poppy_core.bus.results import PingResult
from poppy_core.bus.timing import settle_s, silence_s
from poppy_core.errors import CorruptPacketError
from poppy_core.models import model_by_number

logger = logging.getLogger(__name__)

# Pings, at most, to tell a slow adapter from a busy moment (see doubt_learned).
DOUBT_PINGS = 3
# The wait for each reply when a motor heard at a rate is asked a last time (``ask_patiently``):
# as ``find.PATIENT_LATENCY_S``, longer than a busy machine runs an emulator late.
PATIENT_REPLY_S = 0.15


def ping_found(bus: DxlBus, motor_id: int, retries: int) -> PingResult | None:
    """Ping ``motor_id`` as a search does: garbage in reply counts as no reply."""
    try:
        return bus.ping(motor_id, retries=retries)
    except CorruptPacketError:
        logger.debug("%s: garbage in reply to ping %d", bus.port, motor_id)
        return None


def settle(bus: DxlBus, min_s: float = 0.0) -> set[int]:
    """Listen for replies still on their way (``min_s`` at least); return who answered late.

    The quiet time counts from the last instruction sent: a reply comes that long after its
    instruction at the latest, and whatever came since is kept (the wait for the last reply
    is part of it). Whatever came is dropped, so that the next rate starts on a clean line; an
    adaptive bus has learned from it how slow the adapter really is.
    """
    quiet_s = max(settle_s(bus.latency_s), min_s)
    return {status.id for status in bus.listen(max(0.0, quiet_s - bus.transport.since_written_s()))}


def heard_in_silence(bus: DxlBus, wanted: set[int]) -> dict[int, PingResult]:
    """Listen until ``silence_s`` has passed since the last instruction (the second broadcast).

    Two empty broadcast pings may only mean that the other end was run late past both
    deadlines (see ``poppy_core.bus.scan``).

    Returns:
        The ping replies of ``wanted`` IDs that came late meanwhile (kept aside as strays during
        the second broadcast, or arriving now), by ID.
    """
    quiet_s = silence_s(bus.latency_s) - bus.transport.since_written_s()
    heard: dict[int, PingResult] = {}
    for status in bus.listen(max(0.0, quiet_s)):
        if status.id in wanted and len(status.params) == bus.proto.ping_params:
            number = int.from_bytes(status.params[:2], "little")
            heard[status.id] = PingResult(
                status.id, number, status.params[2], model_by_number(number)
            )
    if heard:
        logger.info(
            "%s: both broadcast pings at %d bps missed late replies from %s: asking again",
            bus.port,
            bus.baudrate,
            ", ".join(map(str, sorted(heard))),
        )
    return heard


def ask_patiently(
    bus: DxlBus, motor_id: int, *, identify: bool = True, heard: set[int] | None = None
) -> PingResult | None:
    """Ask ``motor_id``, heard at this rate but silent when asked again, a last time, patiently.

    Its reply may have been a late one from the rate before (a slow adapter), or the other end
    was run late twice in a row (an emulator on a busy machine: a factory-new MX-28 went
    unfound by ``poppy scan --all-bauds`` when the ping confirming it came 20 ms late). The
    line is left quiet first, so that a late reply from elsewhere is not taken for an answer;
    then a motor really at this rate answers, however late the OS runs it (``PATIENT_REPLY_S``
    a reply, one retry), and an echo from another rate does not. Costs 0.3 s for an echo.
    The IDs whose replies came in the quiet time (or were kept aside before) are added to
    ``heard``: they are late too, and the caller asks them in turn.
    """
    quiet = settle(bus)
    if heard is not None:
        heard.update(quiet)
    with bus.patient(1, PATIENT_REPLY_S):
        try:
            result = bus.ping(motor_id, retries=1, identify=identify)
        except CorruptPacketError:
            return None
    if result is not None:
        logger.info(
            "%s: motor %d answered at %d bps only when asked patiently (a busy machine?)",
            bus.port,
            motor_id,
            bus.baudrate,
        )
    return result


def answers(bus: DxlBus, motor_id: int) -> bool:
    """Whether ``motor_id`` answers a ping (one retry, no model read)."""
    try:
        return bus.ping(motor_id, retries=1, identify=False) is not None
    except CorruptPacketError:
        return False


def doubt_learned(bus: DxlBus, before_s: float, motor_id: int) -> set[int]:
    """Keep the latency learned at this rate only if a motor found at it still needs it.

    A late reply may come from a slow adapter, or from a moment the OS ran the other end late
    (a busy machine). Learned from the latter, a longer wait would cost every silent ID at every
    rate still to scan (one reply 20 ms late made a sweep of 17 rates take 84 s, not 13 s).
    So ``motor_id``, found at this rate, is pinged with the deadline of before, up to
    ``DOUBT_PINGS`` times: one answer on time shows that the adapter keeps up, and the latency
    of before is restored. A slow adapter is late every time (the line is left quiet between
    the pings, so that a late answer is not taken for the next one's); the latency learned stays.

    Returns:
        The other IDs whose replies came meanwhile (late ones: the caller asks them again).
    """
    learned = bus.latency_s
    others: set[int] = set()
    for attempt in range(DOUBT_PINGS):
        if attempt:  # the last ping's late answer, if it is coming
            others.update(status.id for status in bus.listen(settle_s(learned)))
        bus.latency_s = before_s
        try:
            on_time = bus.ping(motor_id, retries=0, identify=False) is not None
        except CorruptPacketError:
            on_time = False
        if on_time:
            logger.info(
                "%s: motor %d answers on time at %.1f ms: a reply was late once, the adapter "
                "is not slower (not waiting %.1f ms)",
                bus.port,
                motor_id,
                before_s * 1000,
                learned * 1000,
            )
            others.update(status.id for status in bus.take_strays())
            return others - {motor_id}
        learned = max(learned, bus.latency_s)
    bus.latency_s = learned
    others |= settle(bus)  # the last ping's late answer must not land at the next rate
    return others - {motor_id}
