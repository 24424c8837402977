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


def _cpu_pairs(base: dict[str, Any], now: dict[str, Any], key: str) -> Pairs:
    """Per scenario: (this µs/request, baseline µs/request, load average) of each round."""
    pairs: Pairs = defaultdict(list)
    for name, measured in now.items():
        if not isinstance(measured, dict) or name not in base:
            continue
        theirs = {run["rep"]: run for run in base[name]["runs"]}
        for run in measured["runs"]:
            other = theirs.get(run["rep"])
            if other is not None and run.get(key) and other.get(key):
                load = (run["load1"] + other["load1"]) / 2
                pairs[name].append((float(run[key]), float(other[key]), load))
    return pairs


def _cpu_cells(pairs: list[tuple[float, float, float]]) -> list[str]:
    """The baseline's median, this one's, and the per-round ratios (median, range, rounds
    where this one used less) of (this, baseline, load) pairs."""
    if not pairs:
        return ["-", "-", "-"]
    ratios = [p[0] / p[1] for p in pairs]
    spread = f"{min(ratios):.2f} – {max(ratios):.2f}"
    less = f"{sum(r < 1 for r in ratios)} of {len(ratios)}"
    return [
        f"{statistics.median(p[1] for p in pairs):.1f}",
        f"{statistics.median(p[0] for p in pairs):.1f}",
        f"{statistics.median(ratios):.3f} ({spread}), {less}",
    ]


def baseline_cpu_table(
    base: dict[str, Any], now: dict[str, Any], label: str
) -> tuple[Table, list[str]]:
    """The side-by-side table of CPU per request (whole process and serving thread)."""
    rows = []
    net = _cpu_pairs(base, now, "net_cpu_us")
    serving = _cpu_pairs(base, now, "serving_cpu_us")
    for name, pairs in _cpu_pairs(base, now, "cpu_us").items():
        rows.append(
            [
                name,
                str(len(pairs)),
                *_cpu_cells(pairs),
                *_cpu_cells(net.get(name, [])),
                *_cpu_cells(serving.get(name, [])),
            ]
        )
    headers = ["scenario", "Rounds"]
    for what in ("process", "process less background", "serving thread"):
        headers += [
            f"{label}: {what} µs/req",
            f"this: {what} µs/req",
            "ratio this / base: median (range), rounds this used less",
        ]
    title = f"This poppy beside poppy {label}: CPU µs per request served, alternated in each round"
    table = Table(title, headers, rows)
    note = (
        "CPU per request: nanoseconds on a CPU of every thread of each server process "
        "(`/proc/PID/task/*/schedstat`) over a run, divided by the requests it served; the "
        "serving thread is the busiest one (uvicorn's). The process figure includes the 50 Hz "
        "sync loops and the emulator, whose share per request grows when a server gets fewer "
        "requests done; less background, it is the process's CPU less what it spent per "
        "second in the 0.5 s without requests just before the run. A ratio below 1 means this "
        "checkout spends less CPU per request. Unlike requests/s, CPU per request holds under "
        "load: load delays a server, it does not make it work more."
    )
    return table, [note]


def calls_table(counts: dict[str, dict[str, Any]], label: str | None) -> tuple[Table, list[str]]:
    """Python calls and in-process CPU per request of each route, for this checkout and, with
    ``label``, the baseline (``counts`` maps "poppy" and the baseline's key to the counts)."""
    sides = list(counts)
    rows = []
    now = counts[sides[0]]
    base = counts[sides[1]] if len(sides) > 1 else {}
    for route, mine in now.items():
        if not isinstance(mine, dict):
            continue
        theirs = base.get(route) if isinstance(base.get(route), dict) else None
        row = [route]
        if label is not None:
            row.append(f"{theirs['calls']:.0f}" if theirs else "-")
        row.append(f"{mine['calls']:.0f}")
        if label is not None:
            row.append(f"{mine['calls'] - theirs['calls']:+.0f}" if theirs else "-")
            row.append(f"{theirs['cpu_us']:.1f}" if theirs else "-")
        row.append(f"{mine['cpu_us']:.1f}")
        rows.append(row)
    headers = ["route"]
    if label is not None:
        headers.append(f"{label}: calls/req")
    headers.append("this: calls/req")
    if label is not None:
        headers += ["difference", f"{label}: µs/req in-process"]
    headers.append("this: µs/req in-process")
    note = (
        "Calls per request: `bench/server_calls.py` starts each checkout's `poppy serve --sim "
        "--http` in its own interpreter and drives uvicorn's HTTP protocol of that server over "
        "an in-memory connection (uvicorn's parser, the connection limits, every middleware, "
        "the route, the answer's encoding; no kernel, no network), 500 requests a route as wrk "
        "sends them; cProfile counts every Python and C function call. The count is "
        "deterministic; the in-process µs (the driving thread's CPU, profiler off) moves a "
        "little with the load. `/robot.json` is counted with its 10 ms cache always hit and "
        "rebuilt for every request (under wrk it is rebuilt about once every 30-100 requests)."
    )
    title = "Python calls per request, counted without a network"
    return Table(title + (f": this poppy beside {label}" if label else ""), headers, rows), [note]
