"""Shared helpers of the peer benchmark scripts (standard library only: the peers venv runs them):
command lines, JSON output, pypot configs, call timing and process status."""

from __future__ import annotations

import argparse
import importlib
import json
import sys
import threading
import time
from collections.abc import Callable
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


def parse_controller_port(text: str) -> tuple[str, str]:
    """``CONTROLLER=PORT`` (an ``--port`` value of the robot scripts) as ``(name, port)``.

    Raises:
        argparse.ArgumentTypeError: not of that form.
    """
    name, sep, port = text.partition("=")
    if not sep or not name or not port:
        raise argparse.ArgumentTypeError(f"expected CONTROLLER=PORT, got {text!r}")
    return name, port


def peer_config(path: str, ports: list[tuple[str, str]] | None = None) -> dict[str, Any]:
    """A pypot robot config read from ``path``, its sensors dropped (the Ergo Jr's camera) and
    its controllers' ports replaced by ``ports`` (``(controller, port)`` pairs)."""
    with open(path) as f:
        config: dict[str, Any] = json.load(f)
    config.pop("sensors", None)
    for name, port in ports or []:
        config["controllers"][name]["port"] = port
    return config


def from_config(
    pypot_robot: Any, config: dict[str, Any], record: dict[str, Any], **options: Any
) -> Any:
    """``pypot.robot.from_config(config, **options)``, or None with ``record["error"]`` saying
    why it failed (pypot raises its DxlError, serial errors, KeyError...)."""
    try:
        return pypot_robot.from_config(config, **options)
    except Exception as exc:
        record["error"] = f"from_config failed: {type(exc).__name__}: {exc}"
        return None


class TimedCalls:
    """Start times of the calls ``wrap`` times (thread-safe), for a rate over a window."""

    def __init__(self) -> None:
        self.starts: list[float] = []
        self._lock = threading.Lock()

    def note(self) -> None:
        """One call starts now."""
        now = time.perf_counter()
        with self._lock:
            self.starts.append(now)

    def wrap(self, update: Callable[[], None]) -> Callable[[], None]:
        """``update``, its starts noted."""

        def timed() -> None:
            self.note()
            update()

        return timed

    def window(self, start_s: float, end_s: float) -> list[float]:
        """The starts between ``start_s`` and ``end_s`` (perf_counter seconds)."""
        with self._lock:
            return [t for t in self.starts if start_s <= t <= end_s]


def proc_status() -> dict[str, int]:
    """VmRSS (kB) and Threads of this process, from /proc/self/status."""
    out: dict[str, int] = {}
    with open("/proc/self/status") as f:
        for line in f.read().splitlines():
            key, _, value = line.partition(":")
            if key in ("VmRSS", "Threads"):
                out[key] = int(value.split()[0])
    return out


def import_peer(record: dict[str, Any], *names: str) -> list[Any] | None:
    """The modules ``names``, the first one's ``__version__`` kept in ``record["version"]``; None
    with ``record["error"]`` saying which import failed (the peer is not installed)."""
    try:
        modules = [importlib.import_module(name) for name in names]
    except ImportError as exc:
        record["error"] = f"import failed: {exc}"
        return None
    record["version"] = str(modules[0].__version__)
    return modules
