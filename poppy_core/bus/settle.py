"""Listening for late replies and asking again: how searches tell a motor from a slow echo."""

from __future__ import annotations

import logging

from poppy_core.bus.dxlbus import DxlBus
from poppy_core.bus.results import PingResult
from poppy_core.bus.timing import settle_s
from poppy_core.errors import CorruptPacketError

logger = logging.getLogger(__name__)


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


def answers(bus: DxlBus, motor_id: int) -> bool:
    """Whether ``motor_id`` answers a ping (one retry, no model read)."""
    try:
        return bus.ping(motor_id, retries=1, identify=False) is not None
    except CorruptPacketError:
        return False
