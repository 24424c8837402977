"""Scan a bus with poppy and print one JSON line (run as ``python -m bench.poppy_client``).

It is the poppy counterpart of bench/peers/pypot_scan.py and sdk_scan.py: each client runs in
its own process and times only its scan, so interpreter start-up is measured apart (and the
same way) for all of them. Besides the found motors it reports, per (protocol, baud rate), the
time spent, the pings sent and poppy's own per-ping deadline, to show where the time goes.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from typing import Any

MAX_SERVO_ID = 253  # e-manual Protocol 1.0/2.0: IDs 0..253; 254 is broadcast.
# e-manual Protocol 2.0, Ping: the status packet carries model number (2 bytes) + firmware (1).
V2_PING_STATUS_PARAMS = 3


def _parse_ids(spec: str) -> list[int]:
    ids: list[int] = []
    for part in filter(None, (p.strip() for p in spec.split(","))):
        low, _, high = part.partition("-")
        ids.extend(range(int(low), int(high or low) + 1))
    if not ids or min(ids) < 0 or max(ids) > MAX_SERVO_ID:
        raise argparse.ArgumentTypeError(f"bad id spec {spec!r} (0..{MAX_SERVO_ID})")
    return ids


def _ping_deadlines_s(port: str, baudrate: int, protocol: int) -> dict[str, float]:
    """poppy's wait for a silent ID at this rate, and the physical round trip inside it.

    ``physical_s`` is the ping and its status on the wire plus the return delay and the adapter
    latency; ``deadline_s`` adds poppy's scheduling margin. Empty when the bus layer's timing
    names cannot be imported (the client still scans).
    """
    try:
        from poppy_core.bus.timing import (
            DEFAULT_RETURN_DELAY_S,
            LinkTiming,
            default_latency_s,
            instruction_size,
            status_size,
        )
    except ImportError:
        return {}
    latency_s = default_latency_s(port)
    timing = LinkTiming(baudrate, DEFAULT_RETURN_DELAY_S, latency_s)
    tx = instruction_size(protocol, 0)
    rx = status_size(protocol, 0 if protocol == 1 else V2_PING_STATUS_PARAMS)
    return {
        "deadline_s": timing.reply_timeout_s(tx, rx),
        "physical_s": timing.wire_s(tx + rx) + DEFAULT_RETURN_DELAY_S + latency_s,
    }


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Import poppy, scan, and return the JSON-ready record."""
    record: dict[str, Any] = {"peer": "poppy", "port": args.port, "error": None}
    start = time.perf_counter()
    import poppy_core
    from poppy_core.bus.results import ScanProgress
    from poppy_core.bus.scan import scan
    from poppy_core.errors import PoppyError

    record["import_s"] = time.perf_counter() - start
    record["version"] = poppy_core.__version__
    protocols = [1, 2] if args.protocol == 0 else [args.protocol]
    baudrates = None if args.all_bauds else [args.baud]
    marks: dict[tuple[int, int], list[float]] = {}  # (protocol, baud) -> [last time, events]

    def on_progress(p: ScanProgress) -> None:
        mark = marks.setdefault((p.protocol, p.baudrate), [0.0, 0.0])
        mark[0] = time.perf_counter()
        mark[1] += 1.0 if p.step == "ping" else 0.0

    start = time.perf_counter()
    try:
        found = scan(
            args.port,
            baudrates,
            protocols,
            args.ids,
            progress=on_progress,
            broadcast=not args.no_broadcast,
        )
    except PoppyError as exc:
        record["error"] = f"scan failed: {type(exc).__name__}: {exc}"
        return record
    end = time.perf_counter()
    record["elapsed_s"] = end - start
    record["found"] = sorted(m.id for m in found)
    record["found_detail"] = sorted([m.protocol, m.baudrate, m.id] for m in found)
    rates = []
    previous = start
    for (protocol, baud), (last, pings) in marks.items():
        rates.append(
            {
                "protocol": protocol,
                "baud": baud,
                "elapsed_s": last - previous,
                "pings": int(pings),
                **_ping_deadlines_s(args.port, baud, protocol),
            }
        )
        previous = last
    record["rates"] = rates
    return record


def main(argv: list[str] | None = None) -> int:
    """Parse the command line, scan, print the JSON line; 0 on success, 1 on error."""
    parser = argparse.ArgumentParser(description="poppy bus scan (benchmark client)")
    parser.add_argument("--port", required=True)
    parser.add_argument("--baud", type=int, default=1_000_000)
    parser.add_argument("--all-bauds", action="store_true", help="every standard rate")
    parser.add_argument("--protocol", type=int, choices=(0, 1, 2), default=0, help="0: both")
    parser.add_argument("--ids", type=_parse_ids, default=_parse_ids(f"0-{MAX_SERVO_ID}"))
    parser.add_argument("--no-broadcast", action="store_true", help="ping each ID (protocol 2)")
    record = run(parser.parse_args(argv))
    sys.stdout.write(json.dumps(record, sort_keys=True) + "\n")
    return 0 if record["error"] is None else 1


if __name__ == "__main__":
    sys.exit(main())
