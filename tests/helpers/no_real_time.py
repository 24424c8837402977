"""Children that cannot make themselves real-time (``preexec_fn=without_real_time``).

SVT-AV1 asks for ``SCHED_FIFO`` 99 when it opens (poppy undoes it: poppy_core/dataset/realtime.py);
a peer's own encoder (LeRobot's, in its venv) would keep it, and as root its threads, and the
processes it starts, would then hold cores the tests' workers never get back. A child started
with this has no ``CAP_SYS_NICE`` (dropped from the bounding set before ``exec``, so root loses
it), so the request fails and the encoder runs at the normal policy.
"""

from __future__ import annotations

import ctypes
import ctypes.util

PR_CAPBSET_DROP = 24
CAP_SYS_NICE = 23


def without_real_time() -> None:
    """In the child, before ``exec``: no real-time policy for it (a no-op where not allowed)."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        libc.prctl(PR_CAPBSET_DROP, CAP_SYS_NICE, 0, 0, 0)
    except (OSError, AttributeError):
        pass
