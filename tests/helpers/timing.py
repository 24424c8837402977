"""Where the suite's time goes: each test's wall and CPU time, per worker, and a summary of them.

`POPPY_TEST_TIMES=DIR pytest ...` makes each test process (each xdist worker) write
``DIR/times-<worker>.json`` (``times-<part>-<worker>.json`` in a part of the suite,
tests/helpers/parts.py): for every test its node id, xdist group, start and end (epoch
seconds, setup and teardown included, so a module fixture counts in its first test), and the
CPU time the process spent meanwhile (its own threads, plus children it waited for).
``python -m tests.helpers.timing DIR`` sums them per module and group, says how much of the
run was waiting, when each worker ran out of work and what ran last (the tail).
"""

from __future__ import annotations

import json
import os
import resource
import sys
import time
from collections import defaultdict
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tests.helpers.parts import PART_ENV

TIMES_ENV = "POPPY_TEST_TIMES"

# The groups that take longest, in seconds of one worker (measured with POPPY_TEST_TIMES; see
# docs/testing.md, "What keeps the suite fast"). Workers take them first, so that no long group
# starts last and runs alone at the end of the run (xdist's own order, most tests first, put the
# LeRobot plugin's few slow tests last). Refresh them when a group grows. Measured 2026-12-06
# (stop 37) on the idle 2-core machine as CI runs it (four workers, `make test` in 10 min 33 s):
# the groups over 20 s.
SLOW_GROUPS_S: dict[str, float] = {
    "cli/test_readme_tour.py": 166,  # 5 tests
    "browser": 159,  # 58 tests
    "creatures/test_doc_examples.py": 152,  # 52 tests
    "creatures/test_creature_packages.py": 102,  # 6 tests
    "lerobot_plugin/test_commands.py": 102,  # 1 test
    "tui/test_session.py": 63,  # 12 tests
    "fleet/test_router.py": 57,  # 12 tests
    "server/test_snap_pypot_blocks.py": 45,  # 4 tests
    "cli/test_setup_doctor.py": 44,  # 20 tests
    "server/test_fuzz.py": 44,  # 2 tests
    "models/test_roundtrip.py": 39,  # 798 tests
    "lerobot_plugin/test_policy_commands.py": 36,  # 1 test
    "cli/test_scan_emulate.py": 34,  # 13 tests
    "tui/test_setup_screen.py": 32,  # 1 test
    "server/test_dataset_recording.py": 31,  # 23 tests
    "cli/test_record_safety.py": 29,  # 7 tests
    "tui/test_robot_tab.py": 27,  # 5 tests
    "server/test_announce.py": 26,  # 3 tests
    "tui/test_pilot.py": 23,  # 9 tests
    "cli/test_service_cmd.py": 23,  # 32 tests
    "tui/test_responsiveness.py": 22,  # 2 tests
    "cli/test_missing_extras.py": 22,  # 18 tests
    "fleet/test_start_time.py": 20,  # 18 tests
    "fleet/test_zenoh_transport_auth.py": 20,  # 3 tests
}


def handout_order(counts: dict[str, int]) -> list[str]:
    """The order ``make test`` hands groups out to its workers: the groups of
    ``SLOW_GROUPS_S``, longest first, then the others by their number of tests, most first, as
    xdist orders them (``counts``: each group's number of tests, in collection order)."""
    first = {group: index for index, group in enumerate(counts)}
    return sorted(counts, key=lambda g: (-SLOW_GROUPS_S.get(g, 0.0), -counts[g], first[g]))


def xdist_order(counts: dict[str, int]) -> list[str]:
    """xdist's own order (``--loadscope-reorder``): most tests first, then collection order."""
    return sorted(counts, key=lambda g: -counts[g])


def _cpu_s() -> float:
    """CPU seconds of this process (all its threads) and of the children it waited for."""
    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def _group(item: pytest.Item) -> str:
    marker = item.get_closest_marker("xdist_group")
    if marker is not None and marker.args:
        return str(marker.args[0])
    return item.nodeid.split("::")[0]


class TimesRecorder:
    """A pytest plugin: records each test's wall and CPU time; writes them at the session's end."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        worker = os.environ.get("PYTEST_XDIST_WORKER", "main")
        part = os.environ.get(PART_ENV, "").strip()  # two parts' workers share their names
        self.worker = f"{part}-{worker}" if part else worker
        self.rows: list[dict[str, Any]] = []
        self.started = time.time()

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_protocol(self, item: pytest.Item) -> Iterator[None]:
        start, cpu = time.time(), _cpu_s()
        yield
        self.rows.append(
            {
                "test": item.nodeid,
                "group": _group(item),
                "start": start,
                "end": time.time(),
                "cpu": _cpu_s() - cpu,
            }
        )

    def pytest_sessionfinish(self) -> None:
        if not self.rows:  # the xdist controller runs no test
            return
        self.folder.mkdir(parents=True, exist_ok=True)
        report = {"worker": self.worker, "started": self.started, "tests": self.rows}
        path = self.folder / f"times-{self.worker}.json"
        path.write_text(json.dumps(report))


def _load(folder: Path) -> list[dict[str, Any]]:
    return [json.loads(path.read_text()) for path in sorted(folder.glob("times-*.json"))]


def summary(folder: Path, top: int = 25) -> str:
    """Per-module and per-group wall and CPU, the waiting share, each worker's end and tail."""
    workers = _load(folder)
    if not workers:
        return f"no times-*.json in {folder}"
    rows = [dict(row, worker=w["worker"]) for w in workers for row in w["tests"]]
    begin = min(w["started"] for w in workers)
    end = max(row["end"] for row in rows)
    wall = sum(row["end"] - row["start"] for row in rows)
    cpu = sum(row["cpu"] for row in rows)
    lines = [
        f"{len(rows)} tests in {len(workers)} process(es), {end - begin:.0f} s from the first "
        f"worker's start to the last test's end",
        f"test time {wall:.0f} s, of which CPU of the test processes {cpu:.0f} s "
        f"({100 * cpu / max(wall, 1e-9):.0f} %), waiting {wall - cpu:.0f} s",
    ]
    for title, key in (("module", "module"), ("group", "group")):
        sums: dict[str, list[float]] = defaultdict(lambda: [0.0, 0.0, 0.0])
        for row in rows:
            name = row["test"].split("::")[0] if key == "module" else row["group"]
            sums[name][0] += row["end"] - row["start"]
            sums[name][1] += row["cpu"]
            sums[name][2] += 1
        lines.append(f"\nslowest {top} by {title} (wall s, CPU s, tests):")
        for name, (w, c, n) in sorted(sums.items(), key=lambda kv: -kv[1][0])[:top]:
            lines.append(f"  {w:7.1f} {c:7.1f} {int(n):5d}  {name}")
    lines.append("\neach worker: last test's end (s after the start), its last group:")
    for w in sorted(workers, key=lambda w: max(r["end"] for r in w["tests"])):
        last = max(w["tests"], key=lambda r: r["end"])
        group_rows = [r for r in w["tests"] if r["group"] == last["group"]]
        first = min(r["start"] for r in group_rows)
        lines.append(
            f"  {w['worker']}: {last['end'] - begin:6.0f} s, {last['group']} "
            f"(from {first - begin:.0f} s, {len(group_rows)} tests)"
        )
    return "\n".join(lines)


def simulate(groups: list[tuple[str, list[float]]], workers: int) -> tuple[float, dict[int, str]]:
    """When a run would end if its groups (each its tests' durations, in the order handed out)
    went to ``workers`` workers as xdist's loadgroup scheduler hands them: one group each, and
    another to a worker whenever two tests or fewer of its own are left (pytest-xdist 3.8,
    ``LoadScopeScheduling._reschedule``). Returns the end and each worker's last group."""
    queue = list(groups)
    pending: list[list[tuple[str, float]]] = [[] for _ in range(workers)]
    clock = [0.0] * workers
    last: dict[int, str] = {}

    def give(worker: int) -> None:
        if queue and len(pending[worker]) <= 2:
            name, durations = queue.pop(0)
            pending[worker].extend((name, d) for d in durations)

    for worker in range(workers):
        give(worker)
    for worker in range(workers):
        give(worker)
    while any(pending):
        worker = min((w for w in range(workers) if pending[w]), key=lambda w: clock[w])
        name, duration = pending[worker].pop(0)
        clock[worker] += duration
        last[worker] = name
        give(worker)
    return max(clock), last


def measured_groups(folder: Path) -> dict[str, list[float]]:
    """Each group's tests' wall times, as recorded in ``folder``."""
    groups: dict[str, list[float]] = defaultdict(list)
    for worker in _load(folder):
        for row in worker["tests"]:
            groups[row["group"]].append(row["end"] - row["start"])
    return dict(groups)


def pytest_configure(config: pytest.Config) -> None:
    """Registers the recorder when ``POPPY_TEST_TIMES`` names a folder (see the docstring)."""
    folder = os.environ.get(TIMES_ENV)
    if folder:
        config.pluginmanager.register(TimesRecorder(Path(folder)), "poppy-test-times")


def compare(folder: Path, workers: list[int]) -> str:
    """The run's end simulated for each worker count in xdist's order and the suite's."""
    groups = measured_groups(folder)
    counts = {name: len(groups[name]) for name in sorted(groups)}  # collection order: by path
    lines = ["\nsimulated end (s) of the groups measured, xdist's order / the suite's order:"]
    for count in workers:
        ends = []
        for order in (xdist_order, handout_order):
            end, last = simulate([(g, groups[g]) for g in order(counts)], count)
            ends.append(f"{end:6.0f} (last: {', '.join(sorted(set(last.values())))[:90]})")
        lines.append(f"  {count} workers: " + " / ".join(ends))
    return "\n".join(lines)


if __name__ == "__main__":
    where = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    print(summary(where))
    print(compare(where, [int(n) for n in sys.argv[2:]] or [4, 6]))
