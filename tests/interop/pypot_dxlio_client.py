"""pypot's own IO against a port: scan, read, write, read back; one JSON line on stdout.

Run by tests/interop/test_pypot_dxlio.py with the peers venv's python (pypot 5.0.2):
``python pypot_dxlio_client.py PORT PROTOCOL FIRST LAST GOAL_DEG``. Standard library and pypot
only. pypot's ``DxlIO`` (protocol 1) or ``Dxl320IO`` (protocol 2) is used as is.
"""

from __future__ import annotations

import json
import sys
import time
from typing import Any

# pypot flushes the port's output before every packet: on a pty, a write that gets no reply and
# that the kernel has not yet moved to the emulator's side is discarded by the next packet's
# flush (docs/emulator.md). These tests check what arrives and its values, not that race: each
# write is given this long before pypot's next packet.
SETTLE_S = 0.3
# pypot waits 50 ms for a reply by default; a loaded machine runs the emulator later than that.
TIMEOUT_S = 1.0
ARRIVAL_S = 20.0


def run(port: str, protocol: int, first: int, last: int, goal: float) -> dict[str, Any]:
    """Scan FIRST..LAST, then torque, goal and present position, each read back."""
    import pypot
    import pypot.dynamixel as dxl

    io_class = dxl.DxlIO if protocol == 1 else dxl.Dxl320IO
    out: dict[str, Any] = {"pypot": pypot.__version__}
    with io_class(port, baudrate=1_000_000, timeout=TIMEOUT_S) as io:
        found = list(io.scan(range(first, last + 1)))
        out["found"] = found
        out["models"] = list(io.get_model(found))
        out["positions_before"] = list(io.get_present_position(found))
        io.enable_torque(found)
        time.sleep(SETTLE_S)
        out["torque_on"] = list(io.is_torque_enabled(found))
        io.set_goal_position({motor_id: goal for motor_id in found})
        time.sleep(SETTLE_S)
        out["goals"] = list(io.get_goal_position(found))
        deadline = time.monotonic() + ARRIVAL_S
        while True:
            present = list(io.get_present_position(found))
            if all(abs(p - goal) < 1.0 for p in present) or time.monotonic() > deadline:
                break
            time.sleep(0.05)
        out["positions_after"] = present
        io.disable_torque(found)
        time.sleep(SETTLE_S)
        out["torque_off"] = list(io.is_torque_enabled(found))
    return out


def main() -> int:
    """Parse the arguments, run, print the record (or the error) as one JSON line."""
    port, protocol, first, last, goal = sys.argv[1:6]
    try:
        record = run(port, int(protocol), int(first), int(last), float(goal))
    except Exception as exc:  # reported to the test, which prints it
        record = {"error": f"{type(exc).__name__}: {exc}"}
    sys.stdout.write(json.dumps(record) + "\n")
    return 0 if "error" not in record else 1


if __name__ == "__main__":
    raise SystemExit(main())
