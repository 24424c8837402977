"""Suite-wide guard: a test stuck where no signal reaches it ends the run with every stack."""

from __future__ import annotations

import faulthandler
import sys
from collections.abc import Iterator

import pytest

# pytest-timeout (120 s, by signal) stops a test that waits in Python. A thread stuck inside a
# C library (an OpenGL driver, a serial ioctl) never sees the signal; this watchdog then prints
# every thread's stack and exits, so CI reports where it hung instead of running out its budget.
HANG_LIMIT_S = 600


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item: pytest.Item) -> Iterator[None]:
    faulthandler.dump_traceback_later(HANG_LIMIT_S, exit=True, file=sys.__stderr__)
    try:
        yield
    finally:
        faulthandler.cancel_dump_traceback_later()
