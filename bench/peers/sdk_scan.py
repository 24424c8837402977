"""Scan a Dynamixel bus with the Robotis dynamixel-sdk ping loop and print one JSON result line.

Run it with the peers venv: ``bench/.venv-peers/bin/python bench/peers/sdk_scan.py
--port /dev/pts/N --baud 1000000 --protocol 2 --ids 0-253``. The SDK is used as its own
examples use it (PortHandler.openPort, setBaudRate, PacketHandler.ping per ID), unmodified.
"""

from __future__ import annotations

import importlib
import sys
import time
from importlib import metadata
from typing import Any

from _common import ScanArgs, emit, parse_scan_args

# Status packet sizes the SDK waits for on a ping (header, id, length, error, checksum):
# e-manual Protocol 1.0 status packet: 6 bytes; Protocol 2.0 ping status: 14 bytes,
# of which the SDK sizes its first wait on the 11-byte minimum.
_PING_RX_BYTES = {1: 6, 2: 11}


def _ping_timeout_s(port_handler_mod: Any, port: Any, protocol: int) -> float:
    """Return the per-ping receive timeout the SDK computes (tx time + 2 x LATENCY_TIMER + 2 ms)."""
    latency_ms = float(port_handler_mod.LATENCY_TIMER)
    tx_ms = float(port.tx_time_per_byte) * _PING_RX_BYTES[protocol]
    return (tx_ms + 2.0 * latency_ms + 2.0) / 1000.0


def run(args: ScanArgs) -> dict[str, Any]:
    """Open the port with the SDK, ping each ID and return the result record.

    Args:
        args: Parsed command line.

    Returns:
        The JSON-ready result; ``error`` is None on success.
    """
    record: dict[str, Any] = {
        "peer": "dynamixel-sdk",
        "port": args.port,
        "baud": args.baud,
        "protocol": args.protocol,
        "ids_scanned": len(args.ids),
        "found": [],
        "models": {},
        "open_s": None,
        "elapsed_s": None,
        "timeout_s": None,
        "error": None,
    }
    if args.timeout_s is not None:
        record["error"] = "dynamixel-sdk has no timeout option (it derives it from LATENCY_TIMER)"
        return record
    try:
        sdk = importlib.import_module("dynamixel_sdk")
        port_handler_mod = importlib.import_module("dynamixel_sdk.port_handler")
    except ImportError as exc:
        record["error"] = f"import failed: {exc}"
        return record
    record["version"] = metadata.version("dynamixel-sdk")
    record["latency_timer_ms"] = int(port_handler_mod.LATENCY_TIMER)

    port = sdk.PortHandler(args.port)
    packet = sdk.PacketHandler(1.0 if args.protocol == 1 else 2.0)
    start = time.perf_counter()
    try:
        if not port.openPort():
            record["error"] = "open failed: openPort returned False"
            return record
        if not port.setBaudRate(args.baud):
            port.closePort()
            record["error"] = f"open failed: setBaudRate({args.baud}) returned False"
            return record
    except Exception as exc:  # pyserial raises SerialException for a bad path
        record["error"] = f"open failed: {type(exc).__name__}: {exc}"
        return record
    record["open_s"] = time.perf_counter() - start
    record["timeout_s"] = _ping_timeout_s(port_handler_mod, port, args.protocol)

    found: list[int] = []
    models: dict[str, int] = {}
    comm_success = int(sdk.COMM_SUCCESS)
    try:
        start = time.perf_counter()
        for servo_id in args.ids:
            model_number, result, _error = packet.ping(port, servo_id)
            if result == comm_success:
                found.append(servo_id)
                models[str(servo_id)] = int(model_number)
        record["elapsed_s"] = time.perf_counter() - start
    except Exception as exc:  # an OSError from the port, e.g. the pty went away
        record["error"] = f"scan failed: {type(exc).__name__}: {exc}"
    finally:
        port.closePort()
    record["found"] = found
    record["models"] = models
    return record


def main(argv: list[str] | None = None) -> int:
    """Parse the command line, run the ping loop, print the JSON line.

    Args:
        argv: Arguments; ``sys.argv[1:]`` when None.

    Returns:
        0 on success, 1 if the scan could not run.
    """
    record = run(parse_scan_args("dynamixel-sdk ping loop", argv))
    emit(record)
    return 0 if record["error"] is None else 1


if __name__ == "__main__":
    sys.exit(main())
