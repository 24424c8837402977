"""The ``emulator`` benchmark's tables, notes and goal (see bench/emulator_bench.py)."""

from __future__ import annotations

import math
import statistics
from collections import defaultdict
from typing import Any

from bench.registry import BenchResult, Table

THIS = "this checkout"
BASELINE = "baseline"
MINIMAL = "minimal responder"
MAX_LOST = 1  # SYNC_WRITEs of 300 pypot may lose on a quiet machine


def percentile(values: list[float], q: float) -> float:
    """The ``q`` quantile (0-1) by nearest rank (0 for no values)."""
    if not values:
        return 0.0
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, max(0, math.ceil(q * len(ordered)) - 1))]


def lost_syncs(record: dict[str, Any] | None, ids: int) -> float | None:
    """SYNC_WRITEs lost (each carries one write per motor), None when the client failed."""
    if not record or record.get("error") or "lost" not in record:
        return None
    return float(record["lost"]) / ids


def _fmt(value: float | None) -> str:
    if value is None:
        return "failed"
    return f"{value:g}" if value == int(value) else f"{value:.2f}"


def _label(raw: dict[str, Any], tree: str) -> str:
    return str(raw["baseline"]) if tree == BASELINE else THIS


def latency_table(raw: dict[str, Any]) -> Table:
    """Write-to-read delay per command and checkout, pooled over the rounds."""
    pooled: dict[tuple[str, str], list[float]] = defaultdict(list)
    for session in raw["sessions"]:
        if session["tree"] == MINIMAL:
            continue
        pooled[(session["mode"], session["tree"])] += session.get("latency_us") or []
    rows = [
        [
            mode,
            _label(raw, tree),
            str(len(values)),
            f"{percentile(values, 0.5):.0f} µs",
            f"{percentile(values, 0.99):.0f} µs",
            f"{max(values, default=0):.0f} µs",
        ]
        for (mode, tree), values in pooled.items()
    ]
    return Table(
        "From a client's write on the pty to the emulator's read of it (PINGs every 5 ms)",
        ["Command", "Checkout", "PINGs", "p50", "p99", "max"],
        rows,
    )


def loss_table(raw: dict[str, Any]) -> Table:
    """SYNC_WRITEs pypot lost, per round, beside the baseline's and the controls."""
    ids, total = raw["ids"], 2 * raw["cycles"]
    by_round: dict[tuple[str, int], dict[str, dict[str, Any]]] = defaultdict(dict)
    for session in raw["sessions"]:
        by_round[(session["mode"], session["rep"])][session["tree"]] = session
    with_baseline = raw["baseline"] is not None
    headers = ["Command", "Round", "Load (1 min)", f"This: lost of {total}"]
    if with_baseline:
        headers.append(f"{raw['baseline']}: lost of {total}")
    headers.append("bench/emulator_minimal.py (emulate's round)")
    headers.append("pypot's gap, write to flush (p50, this)")
    headers.append("Flush skipped (control), this" + (" / baseline" if with_baseline else ""))
    rows = []
    for (mode, rep), trees in by_round.items():
        now = trees.get(THIS, {})
        row = [mode, str(rep + 1), f"{now.get('load1', 0):.1f}"]
        row.append(_fmt(lost_syncs(now.get("pypot"), ids)) if now else "-")
        controls = [_fmt(lost_syncs(now.get("control"), ids))]
        if with_baseline:
            base = trees.get(BASELINE, {})
            row.append(_fmt(lost_syncs(base.get("pypot"), ids)) if base else "-")
            controls.append(_fmt(lost_syncs(base.get("control"), ids)))
        minimal = trees.get(MINIMAL)
        row.append(_fmt(lost_syncs(minimal.get("pypot"), ids)) if minimal else "-")
        gap = ((now.get("pypot") or {}).get("gap_us") or {}).get("p50")
        row.append(f"{gap:g} µs" if gap is not None else "-")
        row.append(" / ".join(controls))
        rows.append(row)
    return Table(
        "pypot 5.0.2 Dxl320IO as is (flush before every packet): SYNC_WRITEs lost", headers, rows
    )


def _moved(run: dict[str, Any]) -> str:
    moved = run.get("moved_us")
    if not moved:
        return "-"
    return f"{moved['p50']:g} / {moved['p99']:g} µs, {moved['over_gap']} of {run.get('count', '-')}"


def bare_table(raw: dict[str, Any]) -> Table:
    """The flush experiment on a bare pty, per round."""
    rows = []
    for run in raw.get("bare_pty") or []:
        rows.append(
            [
                str(run["rep"] + 1),
                "nobody" if run.get("reader") == "none" else "a process blocked in read()",
                f"{run.get('gap_us', 0):g} µs",
                f"{run.get('lost', '-')} of {run.get('count', '-')}"
                if not run.get("error")
                else f"failed: {run['error']}",
                _moved(run),
                f"{run['load1']:.1f}",
            ]
        )
    return Table(
        "No emulator: a write to a bare pty, then the client's output flush; packets discarded",
        [
            "Round",
            "Reading the master",
            "Write to flush",
            "Lost",
            "Kernel worker, write to master's side: p50 / p99, slower than the gap",
            "Load (1 min)",
        ],
        rows,
    )


def goal_met(raw: dict[str, Any]) -> bool | None:
    """Every round of this checkout at most ``MAX_LOST`` lost on each command, and (with a
    baseline) no more lost in all than the baseline in the same rounds; None without pypot."""
    ids = raw["ids"]
    mine: dict[str, list[float]] = defaultdict(list)
    theirs: dict[str, list[float]] = defaultdict(list)
    for session in raw["sessions"]:
        lost = lost_syncs(session.get("pypot"), ids)
        if lost is None:
            continue
        if session["tree"] == THIS:
            mine[session["mode"]].append(lost)
        elif session["tree"] == BASELINE:
            theirs[session["mode"]].append(lost)
    if not mine:
        return None
    quiet = all(max(values) <= MAX_LOST for values in mine.values())
    no_worse = all(sum(mine[mode]) <= sum(theirs[mode]) for mode in theirs)
    return quiet and no_worse


def build_result(raw: dict[str, Any]) -> BenchResult:
    """The report section."""
    tables = [latency_table(raw), bare_table(raw)]
    notes = []
    if any(session.get("pypot") for session in raw["sessions"]):
        tables.append(loss_table(raw))
    else:
        notes.append(f"pypot not measured: {raw['peers_note'] or 'peers venv unavailable'}.")
    loads = [s["load1"] for s in raw["sessions"] if "load1" in s]
    if loads:
        notes.append(
            f"Load average (1 min) when the sessions started: median "
            f"{statistics.median(loads):.1f}, {min(loads):.1f} – {max(loads):.1f} (2 cores: "
            "above 1 the client, the emulator and the kernel's tty worker wait for a core)."
        )
    notes.append(
        "A SYNC_WRITE gets no reply; pypot flushes the port's output before its next packet, "
        "about 15 µs later (the gap column). On a pty the bytes a client wrote sit in the "
        "kernel until a kernel worker moves them to the emulator's side, and that flush "
        "discards what it has not moved yet: no reader, however fast, sees them "
        "(docs/emulator.md); the bare pty's worker column says how often it is slower than "
        "that gap at the moment, with no emulator at all. The control "
        "(same client, output flush skipped) counts what the emulator itself loses; "
        "bench/emulator_minimal.py (one thread blocked in read(), six byte tables, nothing "
        "else) what any emulator would lose at that moment. A write whose bytes the kernel's "
        "worker moves later than pypot's gap is lost whatever reads the master: the worker "
        "column is the floor no emulator can go under (docs/emulator.md has the readers tried, "
        "a process of its own and C included)."
    )
    notes.append(
        f"Goal: pypot loses at most {MAX_LOST} SYNC_WRITE of {2 * raw['cycles']} in every round "
        "on both commands on a quiet machine, and never more than the baseline in the same "
        "rounds under load."
    )
    return BenchResult(
        name="emulator",
        title="Emulator: write-to-read delay on a pty, pypot's writes on poppy emulate and sim",
        intro=(
            "How soon `poppy emulate` and `poppy sim --pty` read what a client writes to their "
            "pty, and how many of pypot's SYNC_WRITEs (pypot flushes the port before every "
            "packet) are lost, in rounds alternated with an older checkout (`--baseline DIR`)."
        ),
        tables=tables,
        notes=notes,
        passed=goal_met(raw),
        raw=raw,
    )
