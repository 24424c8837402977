"""Run ``poppy ARGS`` with every chunk its emulator servers take off their line stamped.

Run as ``python bench/emulator_stamp.py OUT ARGS...`` with the checkout to measure first on
``PYTHONPATH`` (this file imports nothing from ``bench``, so an older checkout runs it as is):
each chunk handed to ``EmulatorServer._put`` (the reader's hand-off, present in every version)
is recorded as (its read time on ``time.perf_counter``, its length), and the list is written to
OUT as JSON when the command exits (Ctrl-C ends ``poppy emulate`` and ``poppy sim``).
``time.perf_counter`` is ``CLOCK_MONOTONIC`` on Linux, shared by every process, so a client's
write times compare with these.
"""

from __future__ import annotations

import atexit
import json
import sys
import time
from typing import Any

from poppy_core.emulator import serving

_stamps: list[tuple[float, int]] = []
_original = serving.EmulatorServer._put


def _stamped(self: Any, data: bytes, *args: Any, **kwargs: Any) -> None:
    # The stamp a server passes itself (a reader that stamps where it reads) wins over the
    # time of the hand-off.
    received_at = kwargs.get("received_at")
    _stamps.append((received_at if received_at else time.perf_counter(), len(data)))
    _original(self, data, *args, **kwargs)


def _dump(path: str) -> None:
    with open(path, "w", encoding="utf-8") as out:
        json.dump(_stamps, out)


def main() -> None:
    """Patch the hand-off, then run the poppy command line."""
    out, args = sys.argv[1], sys.argv[2:]
    serving.EmulatorServer._put = _stamped  # type: ignore[method-assign]
    atexit.register(_dump, out)
    sys.argv = ["poppy", *args]
    from poppy_cli.main import main as poppy_main

    poppy_main()


if __name__ == "__main__":
    main()
