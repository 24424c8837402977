"""Toggle torque with pypot's own IO (flushes the port before every packet); count lost writes.

Run it with the peers venv: ``bench/.venv-peers/bin/python bench/peers/pypot_torque.py
--port /dev/pts/3 --protocol 2 --ids 1-6 --cycles 150``.

Each cycle enables then disables the torque of every motor (``enable_torque`` /
``disable_torque``: one SYNC_WRITE each, no reply), reading ``is_torque_enabled`` back after
each write. A write is *lost* when a motor reads back the previous state. pypot's
``DxlIO``/``Dxl320IO`` flush the input and output buffers of the port before every packet, so a
write still in the port's output queue when the next packet starts is discarded unless the
other end has already read it. Prints one JSON line: ``writes``, ``lost``, ``reads_failed``,
``elapsed_s``, and ``gap_us`` (p50, p95): the time from each SYNC_WRITE's ``write()`` returning
to pypot's next output flush, the window the kernel has to move those bytes to the emulator's
side.

``--keep-output`` is the control: the same client with only the output flush skipped (the input
flush stays), so that what the emulator itself loses is counted apart from what the kernel
discards at the client's flush.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

from _common import emit, import_peer, parse_ids

SYNC_WRITE = 0x83  # the instruction byte in both protocols (e-manual)
INSTRUCTION_AT = {1: 4, 2: 7}  # its offset: FF FF ID LEN INST / FF FF FD 00 ID LEN LEN INST


class GapStamps:
    """Wraps a pyserial port's ``write`` and ``flushOutput`` to time each SYNC_WRITE's gap."""

    def __init__(self, port: Any, protocol: int) -> None:
        at = INSTRUCTION_AT[protocol]
        self.gaps_us: list[float] = []
        self._written_at: float | None = None
        write, flush_output = port.write, port.flushOutput

        def stamped_write(data: bytes) -> Any:
            result = write(data)
            is_sync = len(data) > at and data[at] == SYNC_WRITE
            self._written_at = time.perf_counter() if is_sync else None
            return result

        def stamped_flush() -> Any:
            if self._written_at is not None:
                self.gaps_us.append((time.perf_counter() - self._written_at) * 1e6)
                self._written_at = None
            return flush_output()

        port.write, port.flushOutput = stamped_write, stamped_flush

    def summary(self) -> dict[str, float]:
        """p50 and p95 of the gaps, in µs."""
        ordered = sorted(self.gaps_us)
        if not ordered:
            return {}
        return {
            "p50": round(ordered[len(ordered) // 2], 1),
            "p95": round(ordered[min(len(ordered) - 1, len(ordered) * 95 // 100)], 1),
        }


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
        stamps = GapStamps(io._serial, args.protocol)
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
        gap_us=stamps.summary(),
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
