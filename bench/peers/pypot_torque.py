"""Toggle torque with pypot's own IO (flushes the port before every packet); count lost writes.

Run it with the peers venv: ``bench/.venv-peers/bin/python bench/peers/pypot_torque.py
--port /dev/pts/3 --protocol 2 --ids 1-6 --cycles 150``.

Each cycle enables then disables the torque of every motor (``enable_torque`` /
``disable_torque``: one SYNC_WRITE each, no reply), reading ``is_torque_enabled`` back after
each write. A write is *lost* when a motor reads back the previous state. pypot's
``DxlIO``/``Dxl320IO`` flush the input and output buffers of the port before every packet, so a
write still in the port's output queue when the next packet starts is discarded unless the
other end has already read it. Prints one JSON line: ``writes``, ``lost``, ``reads_failed``,
``elapsed_s``.

``--keep-output`` is the control: the same client with only the output flush skipped (the input
flush stays), so that what the emulator itself loses is counted apart from what the kernel
discards at the client's flush.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

from _common import emit, import_peer, parse_ids


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Open the IO, toggle the torque ``args.cycles`` times, return the JSON-ready record."""
    record: dict[str, Any] = {"peer": "pypot", "error": None, "port": args.port}
    modules = import_peer(record, "pypot", "pypot.dynamixel")
    if modules is None:
        return record
    _, dxl = modules
    io_class = dxl.Dxl320IO if args.protocol == 2 else dxl.DxlIO
    writes = lost = reads_failed = 0
    start = time.perf_counter()
    with io_class(args.port, baudrate=args.baud) as io:
        if args.keep_output:
            io._serial.flushOutput = lambda: None  # the control: flush input only
        for _ in range(args.cycles):
            for enable in (True, False):
                if enable:
                    io.enable_torque(args.ids)
                else:
                    io.disable_torque(args.ids)
                writes += len(args.ids)
                try:
                    states = io.is_torque_enabled(args.ids)
                except Exception:  # a timeout: the write cannot be judged
                    reads_failed += len(args.ids)
                    continue
                if len(states) != len(args.ids):
                    reads_failed += len(args.ids)
                    continue
                lost += sum(1 for state in states if bool(state) != enable)
    record.update(
        writes=writes,
        lost=lost,
        reads_failed=reads_failed,
        elapsed_s=round(time.perf_counter() - start, 3),
    )
    return record


def main() -> int:
    """Parse the command line, run, print one JSON line."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--port", required=True)
    parser.add_argument("--baud", type=int, default=1_000_000)
    parser.add_argument("--protocol", type=int, choices=(1, 2), default=2)
    parser.add_argument("--ids", type=parse_ids, default=parse_ids("1-6"))
    parser.add_argument("--cycles", type=int, default=150)
    parser.add_argument("--keep-output", action="store_true", help="skip the output flush")
    args = parser.parse_args()
    try:
        record = run(args)
    except Exception as exc:  # report, never a traceback on stdout
        record = {"peer": "pypot", "error": f"{type(exc).__name__}: {exc}"}
    emit(record)
    return 0 if record.get("error") is None else 1


if __name__ == "__main__":
    raise SystemExit(main())
