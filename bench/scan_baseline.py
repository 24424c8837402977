"""The scan benchmark's side-by-side of this poppy and an older checkout (``--baseline DIR``).

On a machine others load, two runs minutes apart do not compare: the baseline's scan runs
in the same round as this one's, right before or after it (the order swaps each round), on the
same emulator. Each round gives a ratio (this / baseline); the table reports the medians of
both, the median and range of the per-round ratios, and the load average seen.
"""

from __future__ import annotations

import statistics
import subprocess
from collections import defaultdict
from pathlib import Path
from typing import Any

from bench.registry import Table
from bench.stats import fmt_s

BASELINE_CLIENT = "poppy (baseline)"


def baseline_label(folder: Path) -> str:
    """``<short hash> (<commit date>)`` of the checkout in ``folder``, or its path."""
    try:
        done = subprocess.run(
            ["git", "-C", str(folder), "log", "-1", "--format=%h (%cs)"],
            capture_output=True,
            text=True,
            timeout=10,
            check=False,
        )
    except (OSError, subprocess.TimeoutExpired):
        return str(folder)
    return done.stdout.strip() or str(folder)


def _pairs(runs: list[dict[str, Any]]) -> dict[int, list[tuple[float, float, float]]]:
    """Per protocol: (this, baseline, load average) of each round where both scanned right."""
    by_round: dict[tuple[int, int], dict[str, dict[str, Any]]] = defaultdict(dict)
    for run in runs:
        if run["client"] in ("poppy", BASELINE_CLIENT) and run["ok"]:
            by_round[(run["protocol"], run["rep"])][run["client"]] = run
    pairs: dict[int, list[tuple[float, float, float]]] = defaultdict(list)
    for (protocol, _), both in sorted(by_round.items()):
        if len(both) == 2:
            now, base = both["poppy"], both[BASELINE_CLIENT]
            load = (now.get("load1", 0.0) + base.get("load1", 0.0)) / 2
            pairs[protocol].append((float(now["scan_s"]), float(base["scan_s"]), load))
    return pairs


def baseline_table(runs: list[dict[str, Any]], label: str) -> tuple[Table, list[str]]:
    """The side-by-side table and its note."""
    rows = []
    for protocol, pairs in sorted(_pairs(runs).items()):
        now = statistics.median(p[0] for p in pairs)
        base = statistics.median(p[1] for p in pairs)
        ratios = [p[0] / p[1] for p in pairs]
        loads = [p[2] for p in pairs]
        faster = sum(r < 1 for r in ratios)
        rows.append(
            [
                str(protocol),
                str(len(pairs)),
                fmt_s(base),
                fmt_s(now),
                f"{now / base:.3f}",
                f"{statistics.median(ratios):.3f} ({min(ratios):.2f} – {max(ratios):.2f})",
                f"{faster} of {len(ratios)}",
                f"{statistics.median(loads):.1f} ({min(loads):.1f} – {max(loads):.1f})",
            ]
        )
    table = Table(
        f"This poppy beside poppy {label}, same emulator, alternated in each round",
        [
            "Protocol",
            "Rounds",
            f"{label} (median)",
            "this (median)",
            "Ratio of medians",
            "Per-round ratio: median (range)",
            "Rounds this was faster",
            "Load average (1 min)",
        ],
        rows,
    )
    note = (
        f"Side by side with {label} (`--baseline`): in each round both poppies scan the same "
        "emulator one right after the other, the order swapping each round, so both see the "
        "same load; a ratio below 1 means this checkout is faster. The load average is the "
        "machine's 1-minute figure when each scan started (2 cores, shared with other work: "
        "above 2 the emulator and the client wait for a core, and a reply the OS runs late "
        "costs a ping again or a longer wait, in both)."
    )
    return table, [note]
