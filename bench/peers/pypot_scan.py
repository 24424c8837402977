"""Scan a Dynamixel bus with pypot (DxlIO / Dxl320IO) and print one JSON result line.

Run it with the peers venv: ``bench/.venv-peers/bin/python bench/peers/pypot_scan.py
--port /dev/pts/N --baud 1000000 --protocol 1 --ids 0-253``.
"""

from __future__ import annotations

import sys
import time
from typing import Any

from _common import ScanArgs, emit, import_peer, parse_scan_args


def run(args: ScanArgs) -> dict[str, Any]:
    """Open the port with pypot, scan the IDs and return the result record.

    Args:
        args: Parsed command line.

    Returns:
        The JSON-ready result; ``error`` is None on success.
    """
    record: dict[str, Any] = {
        "peer": "pypot",
        "port": args.port,
        "baud": args.baud,
        "protocol": args.protocol,
        "ids_scanned": len(args.ids),
        "found": [],
        "open_s": None,
        "elapsed_s": None,
        "timeout_s": None,
        "error": None,
    }
    modules = import_peer(record, "pypot", "pypot.dynamixel")
    if modules is None:
        return record
    _, dxl = modules
    io_cls = dxl.Dxl320IO if args.protocol == 2 else dxl.DxlIO
    record["io_class"] = io_cls.__name__
    kwargs: dict[str, Any] = {"baudrate": args.baud}
    if args.timeout_s is not None:
        kwargs["timeout"] = args.timeout_s

    start = time.perf_counter()
    try:
        dxl_io = io_cls(args.port, **kwargs)
    except Exception as exc:  # pypot raises serial.SerialException or its own DxlError
        record["error"] = f"open failed: {type(exc).__name__}: {exc}"
        return record
    record["open_s"] = time.perf_counter() - start
    record["timeout_s"] = float(dxl_io.timeout)
    try:
        start = time.perf_counter()
        found = dxl_io.scan(args.ids)
        record["elapsed_s"] = time.perf_counter() - start
        record["found"] = [int(servo_id) for servo_id in found]
    except Exception as exc:  # a corrupt reply raises pypot's DxlCommunicationError
        record["error"] = f"scan failed: {type(exc).__name__}: {exc}"
    finally:
        dxl_io.close()
    return record


def main(argv: list[str] | None = None) -> int:
    """Parse the command line, run the scan, print the JSON line.

    Args:
        argv: Arguments; ``sys.argv[1:]`` when None.

    Returns:
        0 on success, 1 if the scan could not run.
    """
    record = run(parse_scan_args("pypot bus scan", argv))
    emit(record)
    return 0 if record["error"] is None else 1


if __name__ == "__main__":
    sys.exit(main())
