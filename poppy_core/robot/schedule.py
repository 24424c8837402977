"""Re-export of the schedule leaf (``poppy_core.schedule``) for code that imports it from here."""

from __future__ import annotations

from poppy_core.schedule import Backoff, Periodic, RateMeter, Worker

__all__ = ["Backoff", "Periodic", "RateMeter", "Worker"]
