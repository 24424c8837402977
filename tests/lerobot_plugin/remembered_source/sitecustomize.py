"""In the LeRobot command lines the tests run only: ``inspect.getsource`` remembers its answers.

LeRobot's argument parser (draccus) finds each config field's help by asking for its class's
source, field after field, and Python 3.11 re-reads and re-parses the whole module each time
(the policies' configs, ``typing.py``...): 5-10 s of CPU a command start, most of its CPU. The
sources do not change while a command runs: the same answers, each computed once.
"""

from __future__ import annotations

import functools
import inspect
from typing import Any

_getsource = inspect.getsource


@functools.cache
def _remembered(obj: Any) -> str:
    return _getsource(obj)


def getsource(obj: Any) -> str:
    """``inspect.getsource``, computed once an object (an unhashable one: each time)."""
    try:
        hash(obj)
    except TypeError:
        return _getsource(obj)
    return _remembered(obj)


inspect.getsource = getsource
