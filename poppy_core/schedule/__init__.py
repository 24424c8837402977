"""Loop machinery: drift-free deadlines, a rate meter, a doubling backoff, a worker thread, the
one periodic loop body (``Ticker``, ``Worker.periodic``), the gate an armed start waits at, and
``close_all`` (every closing step, whatever fails)."""

from poppy_core.schedule.closing import close_all
from poppy_core.schedule.pacing import Backoff, Periodic, RateMeter, Ticker, TickGuard
from poppy_core.schedule.worker import Gate, Worker

__all__ = [
    "Backoff",
    "Gate",
    "Periodic",
    "RateMeter",
    "TickGuard",
    "Ticker",
    "Worker",
    "close_all",
]
