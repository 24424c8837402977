"""Registry of benchmarks: functions taking a ``BenchContext`` and returning a result."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

REPO_ROOT = Path(__file__).resolve().parent.parent
BENCH_DIR = REPO_ROOT / "bench"
RESULTS_DIR = BENCH_DIR / "results"
POPPY_PYTHON = REPO_ROOT / ".venv" / "bin" / "python"
POPPY_CLI = REPO_ROOT / ".venv" / "bin" / "poppy"


@dataclass
class BenchContext:
    """What every benchmark receives.

    Attributes:
        repeat: how many times each measurement is repeated (the median is reported).
        peers_python: the peers venv's interpreter, or None when the peers are unavailable.
        peers_note: why the peers are unavailable (empty when they are).
        minutes: duration of the long benchmarks (``soak``), None for their default.
        baseline: another checkout of poppy measured beside this one, alternately, by the
            benchmarks that support it (``scan``, ``server``); None for none.
    """

    repeat: int = 3
    peers_python: Path | None = None
    peers_note: str = ""
    minutes: float | None = None
    baseline: Path | None = None


@dataclass
class Table:
    """A Markdown table of a benchmark section."""

    title: str
    headers: list[str]
    rows: list[list[str]]


@dataclass
class BenchResult:
    """Outcome of one benchmark: tables and notes for the report, raw data for the JSON file.

    Attributes:
        name: registry name (``scan``).
        title: section title in docs/performance.md.
        intro: what is measured, one paragraph.
        tables: the result tables.
        notes: honest remarks (one paragraph each).
        passed: True when every goal was met, False when one was missed, None without goals.
        raw: every measurement, JSON-ready.
    """

    name: str
    title: str
    intro: str
    tables: list[Table] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    passed: bool | None = None
    raw: dict[str, Any] = field(default_factory=dict)


BenchFunc = Callable[[BenchContext], BenchResult]


@dataclass(frozen=True)
class Benchmark:
    """A registered benchmark."""

    name: str
    summary: str
    func: BenchFunc
    long: bool = False


BENCHMARKS: dict[str, Benchmark] = {}


def register(name: str, summary: str, *, long: bool = False) -> Callable[[BenchFunc], BenchFunc]:
    """Decorator adding a benchmark function to ``BENCHMARKS`` under ``name``.

    Args:
        name: the name given on the command line (``python -m bench NAME``).
        summary: one line shown by ``python -m bench --list``.
        long: runs only when named (``python -m bench soak``), not in ``python -m bench``.

    Returns:
        The decorator; it returns the function unchanged.
    """

    def decorate(func: BenchFunc) -> BenchFunc:
        if name in BENCHMARKS:
            raise ValueError(f"benchmark {name!r} registered twice")
        BENCHMARKS[name] = Benchmark(name, summary, func, long)
        return func

    return decorate
