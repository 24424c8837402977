"""The server benchmark's side-by-side of this poppy and an older checkout (``--baseline DIR``).

Both poppies are served at once; in each round of each scenario one is loaded right after the
other, the order swapping each round, so both see the same machine load. Each round gives a
ratio of requests/s (this / baseline, above 1 when this one is faster); the table reports the
medians of both, the median and range of the per-round ratios, and the load average seen.
"""

from __future__ import annotations

import statistics
from collections import defaultdict
from typing import Any

from bench.registry import Table

Pairs = dict[str, list[tuple[float, float, float]]]


def _pairs(base: dict[str, Any], now: dict[str, Any]) -> Pairs:
    """Per scenario: (this req/s, baseline req/s, load average) of each round both ran in."""
    pairs: Pairs = defaultdict(list)
    for name, measured in now.items():
        if not isinstance(measured, dict) or name not in base:
            continue
        theirs = {run["rep"]: run for run in base[name]["runs"]}
        for run in measured["runs"]:
            other = theirs.get(run["rep"])
            if other is not None and run.get("rps") and other.get("rps"):
                load = (run["load1"] + other["load1"]) / 2
                pairs[name].append((float(run["rps"]), float(other["rps"]), load))
    return pairs


def baseline_rps_table(
    base: dict[str, Any], now: dict[str, Any], label: str
) -> tuple[Table, list[str]]:
    """The side-by-side table of requests/s and its note."""
    rows = []
    for name, pairs in _pairs(base, now).items():
        mine = statistics.median(p[0] for p in pairs)
        theirs = statistics.median(p[1] for p in pairs)
        ratios = [p[0] / p[1] for p in pairs]
        loads = [p[2] for p in pairs]
        rows.append(
            [
                name,
                str(len(pairs)),
                f"{theirs:.0f}",
                f"{mine:.0f}",
                f"{mine / theirs:.3f}",
                f"{statistics.median(ratios):.3f} ({min(ratios):.2f} – {max(ratios):.2f})",
                f"{sum(r > 1 for r in ratios)} of {len(ratios)}",
                f"{statistics.median(loads):.1f} ({min(loads):.1f} – {max(loads):.1f})",
            ]
        )
    table = Table(
        f"This poppy beside poppy {label}: requests/s, alternated in each round",
        [
            "scenario",
            "Rounds",
            f"{label} req/s (median)",
            "this req/s (median)",
            "Ratio of medians",
            "Per-round ratio: median (range)",
            "Rounds this was faster",
            "Load average (1 min)",
        ],
        rows,
    )
    note = (
        f"Side by side with {label} (`--baseline`): both servers run at once on the same "
        "machine and in each round the same load hits one right after the other, the order "
        "swapping each round; a ratio above 1 means this checkout serves more requests/s. "
        "The load average is the machine's 1-minute figure when each run started (2 cores "
        "shared with other work: absolute figures drop with it, the ratios much less)."
    )
    return table, [note]
