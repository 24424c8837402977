"""Shared command line and JSON output helpers for the peer benchmark scripts."""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass
from typing import Any

# e-manual (Protocol 1.0 / 2.0): IDs 0..253 address servos, 254 (0xFE) is the broadcast ID.
MAX_SERVO_ID = 253


@dataclass
class ScanArgs:
    """Parsed command line of a peer scan script."""

    port: str
    baud: int
    protocol: int
    ids: list[int]
    timeout_s: float | None


def parse_ids(spec: str) -> list[int]:
    """Parse an ID list such as ``0-253``, ``1,2,3`` or ``1-6,10``.

    Args:
        spec: Comma separated IDs or inclusive ranges ``a-b``.

    Returns:
        The IDs in the order given, without duplicates.

    Raises:
        argparse.ArgumentTypeError: If the spec is malformed or an ID is out of 0..253.
    """
    ids: list[int] = []
    for part in spec.split(","):
        part = part.strip()
        if not part:
            continue
        try:
            if "-" in part:
                low_text, high_text = part.split("-", 1)
                low, high = int(low_text), int(high_text)
                if low > high:
                    raise argparse.ArgumentTypeError(f"empty range {part!r}")
                chunk = list(range(low, high + 1))
            else:
                chunk = [int(part)]
        except ValueError as exc:
            raise argparse.ArgumentTypeError(f"bad id spec {part!r}") from exc
        for servo_id in chunk:
            if not 0 <= servo_id <= MAX_SERVO_ID:
                raise argparse.ArgumentTypeError(f"id {servo_id} outside 0..{MAX_SERVO_ID}")
            if servo_id not in ids:
                ids.append(servo_id)
    if not ids:
        raise argparse.ArgumentTypeError("no ids given")
    return ids


def parse_scan_args(description: str, argv: list[str] | None = None) -> ScanArgs:
    """Parse the common ``--port --baud --protocol --ids [--timeout-s]`` command line.

    Args:
        description: Help text of the calling script.
        argv: Arguments to parse; ``sys.argv[1:]`` when None.

    Returns:
        The parsed arguments.
    """
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--port", required=True, help="serial port path, e.g. /dev/pts/3")
    parser.add_argument("--baud", type=int, default=1_000_000, help="baud rate (default 1000000)")
    parser.add_argument("--protocol", type=int, choices=(1, 2), default=1)
    parser.add_argument("--ids", type=parse_ids, default=parse_ids(f"0-{MAX_SERVO_ID}"))
    parser.add_argument(
        "--timeout-s",
        type=float,
        default=None,
        help="override the library's per-packet timeout (default: the library's own default)",
    )
    ns = parser.parse_args(argv)
    return ScanArgs(
        port=ns.port, baud=ns.baud, protocol=ns.protocol, ids=ns.ids, timeout_s=ns.timeout_s
    )


def emit(record: dict[str, Any]) -> None:
    """Write one JSON line to stdout and flush it.

    Args:
        record: The result to print.
    """
    sys.stdout.write(json.dumps(record, sort_keys=True) + "\n")
    sys.stdout.flush()
