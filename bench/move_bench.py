"""Move files benchmark: size and load time of a long move, poppy's format against pypot's JSON.

The move is synthetic and deterministic: 10 minutes of 25 motors at 50 Hz (30 001 frames),
each motor a sum of two sines. It is written once in poppy's format (``.move``) and once as
pypot's JSON by poppy's writer, then loaded ``repeat`` times by poppy (both formats, in this
process, warm file cache) and by pypot's own ``pypot.primitive.move.Move.load`` (the JSON file,
in the peers venv, through ``bench/peers/pypot_move_load.py``).
"""

from __future__ import annotations

import logging
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from bench.clients import run_client
from bench.registry import BENCH_DIR, BenchContext, BenchResult, Table, register
from bench.stats import fmt_range, fmt_ratio, fmt_s, summary
from poppy_core.motion import Move, read_move, write_move

logger = logging.getLogger(__name__)

DURATION_S = 600
MOTORS = 25
FRAMERATE = 50.0
PEER_SCRIPT = BENCH_DIR / "peers" / "pypot_move_load.py"


def synthetic_move() -> Move:
    """The benchmark's move: deterministic, smooth, every motor different."""
    t = np.arange(int(DURATION_S * FRAMERATE) + 1) / FRAMERATE
    columns = [
        40 * np.sin(2 * np.pi * t / (4 + i)) + 10 * np.sin(2 * np.pi * t / (0.7 + i / 10))
        for i in range(MOTORS)
    ]
    return Move(
        FRAMERATE,
        [f"m{i + 1}" for i in range(MOTORS)],
        np.column_stack(columns),
        metadata={"created": "2026-01-01T00:00:00+00:00", "robot": "synthetic"},
    )


def _timed(func: Callable[[], object], repeat: int) -> list[float]:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        func()
        times.append(time.perf_counter() - start)
    return times


def _measure(move: Move, folder: Path, repeat: int) -> dict[str, Any]:
    ours = folder / "long.move"
    theirs = folder / "long.json"
    raw: dict[str, Any] = {}
    for key, path in (("poppy", ours), ("pypot_json", theirs)):
        save = _timed(lambda p=path: write_move(move, p), repeat)  # type: ignore[misc]
        load = _timed(lambda p=path: read_move(p), repeat)  # type: ignore[misc]
        loaded = read_move(path)
        raw[key] = {
            "size_bytes": path.stat().st_size,
            "save_s": save,
            "load_s": load,
            "max_error_deg": float(np.max(np.abs(loaded.positions - move.positions))),
        }
    return raw


def _peer(ctx: BenchContext, json_file: Path) -> dict[str, Any]:
    if ctx.peers_python is None:
        return {"error": f"peers not measured: {ctx.peers_note}", "load_s": []}
    run = run_client(
        [
            str(ctx.peers_python),
            str(PEER_SCRIPT),
            "--file",
            str(json_file),
            "--repeat",
            str(ctx.repeat),
        ]
    )
    return run.record


@register("moves", "size and load time of a 10-min 25-motor 50 Hz move: poppy vs pypot JSON")
def move_bench(ctx: BenchContext) -> BenchResult:
    """Measure the move formats and loaders (see the module docstring)."""
    move = synthetic_move()
    with tempfile.TemporaryDirectory(prefix="poppy-move-bench-") as tmp:
        folder = Path(tmp)
        logger.info("moves: %d frames × %d motors, poppy side", len(move), MOTORS)
        raw = _measure(move, folder, ctx.repeat)
        logger.info("moves: pypot's Move.load on the JSON file (quadratic: takes a while)")
        raw["pypot_load"] = _peer(ctx, folder / "long.json")
    raw["frames"] = len(move)
    raw["motors"] = MOTORS
    return _result(raw, ctx)


def _result(raw: dict[str, Any], ctx: BenchContext) -> BenchResult:
    ours = summary(raw["poppy"]["load_s"])
    json_ours = summary(raw["pypot_json"]["load_s"])
    peer = raw["pypot_load"]
    peer_stats = summary(peer.get("load_s") or [])
    peer_median = peer_stats["median"] if peer_stats["n"] else None
    size_ours = raw["poppy"]["size_bytes"]
    size_json = raw["pypot_json"]["size_bytes"]
    headers = ["file / loader", "file size", "load (median)", "load (min – max)", "× poppy"]
    rows = [
        [
            "poppy `.move`, poppy `read_move`",
            f"{size_ours / 1e6:.1f} MB",
            fmt_s(ours["median"]),
            fmt_range(ours),
            "1×",
        ],
        [
            "pypot JSON, poppy `read_move`",
            f"{size_json / 1e6:.1f} MB",
            fmt_s(json_ours["median"]),
            fmt_range(json_ours),
            fmt_ratio(json_ours["median"], ours["median"]),
        ],
        [
            f"pypot JSON, pypot {peer.get('version', '')} `Move.load`".replace("  ", " "),
            f"{size_json / 1e6:.1f} MB",
            fmt_s(peer_median),
            fmt_range(peer_stats) if peer_stats["n"] else "-",
            fmt_ratio(peer_median, ours["median"]),
        ],
    ]
    saves = Table(
        "Saving (poppy's writer, atomic: temporary file, fsync, rename)",
        ["format", "save (median)", "largest position error after reload"],
        [
            [
                "poppy `.move` (float32)",
                fmt_s(summary(raw["poppy"]["save_s"])["median"]),
                f"{raw['poppy']['max_error_deg']:.1e}°",
            ],
            [
                "pypot JSON",
                fmt_s(summary(raw["pypot_json"]["save_s"])["median"]),
                f"{raw['pypot_json']['max_error_deg']:.1e}°",
            ],
        ],
    )
    notes = [
        f"Each load is repeated {ctx.repeat} times; poppy's loads run in the benchmark process "
        "with the file in the page cache, pypot's in the peers venv (its import time, "
        f"{fmt_s(peer.get('import_s'))}, is not counted).",
        "pypot keeps frames in a `KDTreeDict` whose `update` checks each new key against a "
        "Python list of the keys already there, so its load time grows with the square of "
        "the number of frames; most of its time goes there, not into parsing JSON.",
        "poppy's `.move` stores float32 degrees: the error after reload is far below a "
        "servo's resolution (0.088° on MX/X, 0.29° on AX/XL-320). Use `encode_move(move, "
        "dtype='<f8')` for exact float64.",
    ]
    if peer.get("error"):
        notes.append(f"pypot not measured: {peer['error']}.")
    return BenchResult(
        name="moves",
        title="Move files: a 10-minute, 25-motor, 50 Hz move",
        intro=(
            f"A synthetic move of {raw['frames']} frames × {raw['motors']} motors (10 min at "
            "50 Hz) saved in poppy's compact `.move` format and as pypot's move JSON, then "
            "loaded by poppy and by pypot's own `pypot.primitive.move.Move.load`. No goal "
            'is set by the issue beyond "compact and fast to load"; the ratios say how much.'
        ),
        tables=[Table("Loading the move", headers, rows), saves],
        notes=notes,
        passed=None,
        raw=raw,
    )
