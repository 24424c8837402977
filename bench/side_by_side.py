"""A server measured against pypot's: both sides run, the median rows, milliseconds, percentiles."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from bench.registry import BenchContext

SIDES = ("poppy", "pypot")
COLUMNS = ("req/s", "p50", "p99", "errors")


def measure_sides(
    ctx: BenchContext,
    measure: Callable[[str, BenchContext], dict[str, Any]],
    server: str,
    failures: tuple[type[Exception], ...] = (RuntimeError,),
) -> tuple[dict[str, Any], list[str]]:
    """poppy's figures, then pypot's when its venv is there; the notes on what was not measured."""
    raw: dict[str, Any] = {"poppy": measure("poppy", ctx)}
    notes: list[str] = []
    if ctx.peers_python is None:
        notes.append(f"pypot not measured: {ctx.peers_note}")
        return raw, notes
    try:
        raw["pypot"] = measure("pypot", ctx)
    except failures as exc:
        notes.append(f"pypot's {server} could not be measured: {exc}")
    return raw, notes


def median(raw: dict[str, Any], side: str, scenario: str) -> dict[str, Any] | None:
    """The median run of one side on one scenario, None when it was not measured."""
    found: dict[str, Any] | None = raw.get(side, {}).get(scenario, {}).get("median")
    return found


def median_cells(raw: dict[str, Any], scenario: str, errors: str = "errors") -> list[str]:
    """req/s, p50, p99 and errors of both sides (``-`` where a side was not measured)."""
    cells: list[str] = []
    for side in SIDES:
        run = median(raw, side, scenario)
        if run is None:
            cells += ["-"] * len(COLUMNS)
            continue
        cells += [f"{run['rps']:.0f}", ms(run["p50_s"]), ms(run["p99_s"]), str(run[errors])]
    return cells


def headers(first: str = "scenario") -> list[str]:
    """The first column's name, then the columns of ``median_cells``."""
    return [first, *(f"{side} {column}" for side in SIDES for column in COLUMNS)]


def ms(value: float | None) -> str:
    """Seconds as milliseconds with two decimals, ``-`` for none."""
    return "-" if value is None else f"{value * 1000:.2f} ms"


def percentile(ordered: Sequence[float], q: float) -> float | None:
    """The ``q`` quantile (0-1) of sorted values, None for none."""
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))] if ordered else None
