"""The start spread of ``bench fleet``: ``fleet run`` and ``fleet play`` on 20 robots with a
shared start time, each robot logging when its start began (``bench.fleet_robots --starts``)."""

from __future__ import annotations

import time
from collections import defaultdict
from pathlib import Path
from typing import Any

from bench.fleet_procs import robot_processes
from bench.side_by_side import percentile

TRIALS = 50
"""Fleet play commands timed (after one warm-up): enough for a p90 and a max that mean something
(the goal is checked on the max, a bound over every trial)."""

STARTS = {
    "run": ("/api/v1/primitives/sinus/start", None, "/api/v1/primitives/sinus/stop"),
    "play": ("/api/v1/moves/wave/play", {"speed": 1.0}, "/api/v1/moves/wave/stop"),
}
"""What each start measures: ``fleet run sinus`` and ``fleet play wave`` (start, body, stop)."""


def _wave(moves: Path) -> dict[str, str]:
    """Save the move ``fleet play`` plays in ``moves`` (1 s of ``m1`` from its rest pose and
    back); the robots' environment that makes it their library."""
    from poppy_core.motion.move import Move
    from poppy_core.motion.move_library import MOVES_DIR_ENV, save_move

    moves.mkdir(parents=True, exist_ok=True)
    frames = [{"m1": 10.0 * (1 - abs(1 - i / 25))} for i in range(51)]
    save_move(Move.from_frames(50.0, frames), moves / "wave.move")
    return {MOVES_DIR_ENV: str(moves)}


def play_spread(tmp: Path, router: str | None = None) -> dict[str, Any]:
    from poppy_core.remote.zenoh_fleet import Fleet
    from poppy_core.zenoh_wire import ZenohSettings

    starts = tmp / "starts.txt"
    env = _wave(tmp / "moves")
    found: dict[str, Any] = {}
    with robot_processes(zenoh=True, ws=False, starts=starts, env=env, router=router) as (
        _,
        served,
    ):
        names = [r["name"] for r in served]
        settings = ZenohSettings(connect=tuple({r["endpoint"]: 0 for r in served}))
        with Fleet(settings, timeout_s=5.0) as fleet:
            fleet.wait_for(names, 10.0)
            for what, (path, body, stop) in STARTS.items():
                found[what] = _spread(fleet, names, starts, path, body, stop)
    return found


def _spread(
    fleet: Any, names: list[str], starts: Path, path: str, body: Any, stop: str
) -> dict[str, Any]:
    """``TRIALS`` starts of ``path`` on every robot together (after a first one kept apart)."""
    spreads, offsets, within = [], [], []
    first: dict[str, float] = {}
    for trial in range(TRIALS + 1):
        starts.write_text("")
        outcomes = fleet.command(names, "POST", path, body)
        assert all(o.ok for o in outcomes), [o.message for o in outcomes if not o.ok]
        stamps = _stamps(starts, len(names))
        times = [t for _, t in stamps]
        late = [t - (fleet.last_start_at or 0) for t in times]
        if trial == 0:
            first = {
                "spread_ms": (max(times) - min(times)) * 1000,
                "late_max_ms": max(late) * 1000,
            }
        else:
            spreads.append(max(times) - min(times))
            offsets.extend(late)
            within.append(_within_process(stamps))
        fleet.command(names, "POST", stop, together=False)
    spreads.sort()
    offsets.sort()
    within.sort()
    return {
        "trials": len(spreads),
        "spread_p50_ms": (percentile(spreads, 0.5) or 0) * 1000,
        "spread_p90_ms": (percentile(spreads, 0.9) or 0) * 1000,
        "spread_p99_ms": (percentile(spreads, 0.99) or 0) * 1000,
        "spread_max_ms": spreads[-1] * 1000,
        "late_p50_ms": (percentile(offsets, 0.5) or 0) * 1000,
        "late_p99_ms": (percentile(offsets, 0.99) or 0) * 1000,
        "late_min_ms": offsets[0] * 1000,
        "within_p50_ms": (percentile(within, 0.5) or 0) * 1000,
        "within_max_ms": within[-1] * 1000,
        "first": first,
    }


def _stamps(path: Path, count: int, timeout_s: float = 5.0) -> list[tuple[str, float]]:
    """The ``count`` (process, start time) the robots logged (a robot's primitive begins in its
    own thread, maybe just after the command's reply)."""
    deadline = time.monotonic() + timeout_s
    while True:
        lines = path.read_text().splitlines()
        if len(lines) >= count or time.monotonic() > deadline:
            return [(line.split()[0], float(line.split()[1])) for line in lines]
        time.sleep(0.01)


def _within_process(stamps: list[tuple[str, float]]) -> float:
    """The largest spread of the starts of the robots served by one process."""
    by_process: dict[str, list[float]] = defaultdict(list)
    for pid, stamp in stamps:
        by_process[pid].append(stamp)
    return max(max(times) - min(times) for times in by_process.values())
