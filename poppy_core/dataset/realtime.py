"""Threads an encoder made real-time, put back to the normal policy.

SVT-AV1 (the AV1 encoder of PyAV's wheels) asks for ``SCHED_FIFO`` priority 99 when it opens:
as root it gets it, for the calling thread and the ~50 threads it starts (measured with
PyAV 18.1's libSvtAv1Enc 4.1). A real-time encoder on a 2-core robot starves its sync loop and its
servers, and every thread or process the caller starts afterwards inherits the policy (a busy
one never yields a core). Without root the request fails and nothing changes.
"""

from __future__ import annotations

import logging
import os

logger = logging.getLogger(__name__)

_TASKS = "/proc/self/task"
REALTIME_POLICIES = frozenset(
    getattr(os, name) for name in ("SCHED_FIFO", "SCHED_RR") if hasattr(os, name)
)


def realtime_threads() -> set[int]:
    """This process's threads under a real-time policy (their ids; empty where unknown)."""
    if not REALTIME_POLICIES or not os.path.isdir(_TASKS):
        return set()
    found = set()
    for name in os.listdir(_TASKS):
        try:
            if os.sched_getscheduler(int(name)) in REALTIME_POLICIES:
                found.add(int(name))
        except OSError:  # the thread ended meanwhile
            continue
    return found


def undo_realtime(kept: set[int] | frozenset[int] = frozenset()) -> int:
    """Every real-time thread of this process not in ``kept`` back to the normal policy; how
    many were."""
    undone = 0
    for thread in realtime_threads() - set(kept):
        try:
            os.sched_setscheduler(thread, os.SCHED_OTHER, os.sched_param(0))
        except OSError:
            continue
        undone += 1
    if undone:
        logger.debug("%d real-time thread(s) put back to the normal policy", undone)
    return undone


def calling_thread_realtime() -> bool:
    """Whether the calling thread runs under a real-time policy (cheap: one system call)."""
    return bool(REALTIME_POLICIES) and os.sched_getscheduler(0) in REALTIME_POLICIES
