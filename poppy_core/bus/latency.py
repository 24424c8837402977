"""Learning an adapter's real latency from when replies arrive, late ones included.

A scan on an adapter slower than assumed (a USB latency timer left at 16 ms on an unknown
chip, a network bridge) would give up on replies that are still coming, and take them for
answers to later pings. When a bus learns (``BusCore.adaptive_latency``), each reply is timed
from the instruction sent to its motor; replies that came after the deadline they were given
raise the latency assumed, so the next deadlines wait long enough.

Only a late reply teaches. One that came within its deadline, if slower than the latency
assumed, shows that the deadlines already work (their scheduling margin is there for a side the
OS ran a little late); learning from it raised the latency on an adapter answering on time, and
lengthened every later wait (a scan at 1 Mbps took 1.05 s instead of 0.77 s). A scan's pass
over every ID keeps its deadline whatever is learned meanwhile (see ``poppy_core.bus.scan``).
"""

from __future__ import annotations

from collections import deque
from typing import NamedTuple

from poppy_core.bus.timing import LinkTiming, status_size
from poppy_core.protocol import StatusPacket

# A learned latency is the latency a late reply showed, with this much margin, up to this ceiling.
LEARNED_MARGIN = 1.5
MAX_LEARNED_LATENCY_S = 0.3
# Unanswered instructions kept per motor, and how old one may be before it is forgotten.
PENDING_PER_MOTOR = 8
FORGET_AFTER_S = 2 * MAX_LEARNED_LATENCY_S


class ReplyTime(NamedTuple):
    """How long a reply took, against what its deadline allowed (both less the wire's part).

    Attributes:
        latency_s: the latency the reply shows: elapsed time less wire times and return delay.
        allowed_s: the latency its deadline allowed: the assumed latency plus the margin.
    """

    latency_s: float
    allowed_s: float

    @property
    def late(self) -> bool:
        """True when the reply came after its deadline."""
        return self.latency_s > self.allowed_s


class ReplyClock:
    """When each motor was sent instructions still unanswered, to time their replies.

    Which instruction a late reply answers is not written in it: a retry may have been sent
    before it came, and instructions at a rate the motor does not hear are never answered. A
    reply is taken as the answer to the newest instruction sent at least the assumed latency
    before it (never earlier than it could have come back). That may make it look faster than
    it is, never much slower; the learned latency's margin and the next replies correct it.
    """

    def __init__(self) -> None:
        self._sent: dict[int, deque[tuple[float, int]]] = {}
        self._broadcast: tuple[float, int] | None = None

    def sent(self, motor_id: int, at_s: float, tx_bytes: int) -> None:
        """Record an instruction of ``tx_bytes`` bytes sent to ``motor_id`` at ``at_s``."""
        pending = self._sent.setdefault(motor_id, deque(maxlen=PENDING_PER_MOTOR))
        while pending and at_s - pending[0][0] > FORGET_AFTER_S:
            pending.popleft()
        pending.append((at_s, tx_bytes))

    def sent_to_all(self, at_s: float, tx_bytes: int) -> None:
        """Record a broadcast instruction that every motor answers (protocol 2 ping)."""
        self._broadcast = (at_s, tx_bytes)

    def forget(self) -> None:
        """Forget every pending instruction (the line was flushed or reopened)."""
        self._sent.clear()
        self._broadcast = None

    def learn(
        self, status: StatusPacket, at_s: float, timing: LinkTiming, protocol: int
    ) -> float | None:
        """Time a reply; the latency to assume from now on, None to keep ``timing``'s.

        Only a reply that came after its deadline teaches (see the module docstring).
        """
        took = self.time_of(status, at_s, timing, protocol)
        if took is None or not took.late:
            return None
        learned = learned_latency_s(took.latency_s)
        return learned if learned > timing.latency_s else None

    def time_of(
        self, status: StatusPacket, at_s: float, timing: LinkTiming, protocol: int
    ) -> ReplyTime | None:
        """How long a reply arriving at ``at_s`` took, None when nothing was sent to it.

        The wire times and return delay are taken off the elapsed time; what is left is the
        adapter's latency (plus the OS's delay in reading, which errs on the safe side).
        """
        pending = self._sent.get(status.id)
        entry = self._broadcast
        if pending:
            old_enough = [e for e in pending if at_s - e[0] >= timing.latency_s]
            entry = old_enough[-1] if old_enough else pending[0]
            while pending and pending[0][0] <= entry[0]:
                pending.popleft()
        if entry is None:
            return None
        sent_at, tx_bytes = entry
        rx_bytes = status_size(protocol, len(status.params))
        physical = timing.wire_s(tx_bytes) + timing.return_delay_s + timing.wire_s(rx_bytes)
        allowed = timing.reply_timeout_s(tx_bytes, rx_bytes) - physical
        return ReplyTime(at_s - sent_at - physical, allowed)


def learned_latency_s(observed_s: float) -> float:
    """The latency to assume after a reply showed ``observed_s``."""
    return min(MAX_LEARNED_LATENCY_S, observed_s * LEARNED_MARGIN)
