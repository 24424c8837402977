"""The soak's figures: recovery times, healthy rates, lost writes, resources, verdicts."""

from __future__ import annotations

import statistics
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from bench.registry import BenchResult, Table

TARGET_HZ = 50.0
RATE_TOLERANCE = 0.02
GOAL_OFFLINE_S = 0.5
GOAL_BACK_S = 1.5
GOAL_CLOSE_S = 1.0
GOAL_RSS_GROWTH = 0.10
# A rate is judged on whole seconds away from the faults: from MARGIN_BEFORE_S before a fault
# starts to MARGIN_AFTER_S after it ends.
MARGIN_BEFORE_S = 1.0
MARGIN_AFTER_S = 3.0


@dataclass(frozen=True)
class FaultEvent:
    """A fault as injected: seconds after the client was ready, kind, motor id or bus, length."""

    t_s: float
    kind: str
    target: str
    duration_s: float


def _windows(events: Iterable[FaultEvent]) -> list[tuple[float, float]]:
    return [(e.t_s - MARGIN_BEFORE_S, e.t_s + e.duration_s + MARGIN_AFTER_S) for e in events]


def healthy_rate(bins: list[int], excluded: list[tuple[float, float]], duration_s: float) -> float:
    """Mean count per second over whole seconds outside ``excluded`` (first and last left out)."""
    seconds = [
        s
        for s in range(1, int(duration_s) - 1)
        if s < len(bins) and not any(a < s + 1 and s < b for a, b in excluded)
    ]
    return statistics.fmean(bins[s] for s in seconds) if seconds else 0.0


def _first(transitions: list[list[Any]], name: str, online: bool, after_s: float) -> float | None:
    for t, who, up in transitions:
        if who == name and bool(up) is online and t >= after_s:
            return float(t)
    return None


def _latency(at: float | None, since: float) -> float | None:
    return None if at is None else max(0.0, at - since)


def poppy_metrics(record: dict[str, Any], events: list[FaultEvent]) -> dict[str, Any]:
    """Figures of one poppy run (see the module doc of bench.soak_bench)."""
    motors: dict[str, dict[str, Any]] = record["motors"]
    name_of = {str(info["id"]): name for name, info in motors.items()}
    transitions = record["transitions"]
    duration = float(record["duration_s"])
    unplugs = [e for e in events if e.kind == "unplug"]
    losses = [e for e in events if e.kind == "lose"]
    off: list[float | None] = []
    back: list[float | None] = []
    for e in unplugs:
        name = name_of[e.target]
        off.append(_latency(_first(transitions, name, False, e.t_s - 0.05), e.t_s))
        end = e.t_s + e.duration_s
        back.append(_latency(_first(transitions, name, True, end), end))
    bus_off: list[float | None] = []
    bus_back: list[float | None] = []
    for e in losses:
        on_bus = [n for n, info in motors.items() if info["bus"] == e.target]
        times = [_first(transitions, n, False, e.t_s - 0.05) for n in on_bus]
        bus_off.append(None if None in times else max(_latency(t, e.t_s) or 0.0 for t in times))
        end = e.t_s + e.duration_s
        times = [_first(transitions, n, True, end) for n in on_bus]
        bus_back.append(None if None in times else max(_latency(t, end) or 0.0 for t in times))
    explained = {
        n: _windows(
            e
            for e in events
            if (e.kind == "unplug" and name_of[e.target] == n)
            or (e.kind == "lose" and motors[n]["bus"] == e.target)
        )
        for n in motors
    }
    spurious = [
        (t, n)
        for t, n, up in transitions
        if not up and not any(a <= t <= b for a, b in explained[n])
    ]
    loop_hz = {
        bus: healthy_rate(bins, _windows(e for e in losses if e.target == bus), duration)
        for bus, bins in record["reads_per_s"].items()
    }
    motor_hz = {
        name: healthy_rate(record["updates_per_s"].get(name, []), explained[name], duration)
        for name in motors
    }
    return {
        "duration_s": duration,
        "unplugs": len(unplugs),
        "losses": len(losses),
        "offline_s": off,
        "back_s": back,
        "bus_offline_s": bus_off,
        "bus_back_s": bus_back,
        "spurious_offline": len(spurious),
        "loop_hz": loop_hz,
        "motor_hz": motor_hz,
        "goal_checks": record["goal_checks"],
        "start": record["start"],
        "end": record["end"],
        "alive": record["alive"],
        "close_s": record["close_s"],
    }


def pypot_metrics(record: dict[str, Any], events: list[FaultEvent]) -> dict[str, Any]:
    """Figures of one pypot run: loop rates before the first loss of its bus and after it."""
    duration = float(record["duration_s"])
    before: dict[str, float] = {}
    last: dict[str, float] = {}
    for bus, bins in record["reads_per_s"].items():
        losses = [e for e in events if e.kind == "lose" and e.target == bus]
        first = min(losses, key=lambda e: e.t_s, default=None)
        if first is None:
            before[bus] = healthy_rate(bins, [], duration)
            last[bus] = before[bus]
            continue
        before[bus] = healthy_rate(bins, [(first.t_s - MARGIN_BEFORE_S, duration + 1)], duration)
        back = first.t_s + first.duration_s + MARGIN_AFTER_S
        last[bus] = healthy_rate(bins, [(-1.0, back)], duration)
    return {
        "duration_s": duration,
        "loop_hz_before_loss": before,
        "loop_hz_after_loss": last,
        "loop_errors": record.get("loop_errors", {}),
        "last_errors": record.get("last_errors", {}),
        "start": record["start"],
        "end": record["end"],
        "alive": record["alive"],
        "close_s": record.get("close_s"),
    }


def _fmt_s(values: list[float | None]) -> str:
    known = [v for v in values if v is not None]
    missing = len(values) - len(known)
    if not known:
        return "-" if not values else f"never ({missing})"
    text = f"median {statistics.median(known) * 1000:.0f} ms, max {max(known) * 1000:.0f} ms"
    return text + (f", {missing} never" if missing else "")


def _max(values: list[float | None]) -> float:
    return float("inf") if None in values else max((v or 0.0 for v in values), default=0.0)


def _verdicts(m: dict[str, Any]) -> dict[str, bool]:
    low = TARGET_HZ * (1 - RATE_TOLERANCE)
    rss0, rss1 = m["start"]["VmRSS"], m["end"]["VmRSS"]
    return {
        "loop": all(hz >= low for hz in m["loop_hz"].values()),
        "motor": min(m["motor_hz"].values()) >= low,
        "offline": _max(m["offline_s"]) < GOAL_OFFLINE_S,
        "bus_offline": _max(m["bus_offline_s"]) < GOAL_OFFLINE_S,
        "back": _max(m["back_s"]) < GOAL_BACK_S,
        "bus_back": _max(m["bus_back_s"]) < GOAL_BACK_S,
        "writes": m["goal_checks"]["lost"] == 0,
        "rss": rss1 <= rss0 * (1 + GOAL_RSS_GROWTH),
        "threads": m["end"]["Threads"] == m["start"]["Threads"],
        "alive": all(m["alive"]["sync"].values()) and m["alive"]["primitive"],
        "close": m["close_s"] < GOAL_CLOSE_S,
    }


def _ok(flag: bool) -> str:
    return "yes" if flag else "**no**"


def _poppy_table(results: dict[str, dict[str, Any]]) -> tuple[Table, bool]:
    keys = list(results)
    rows: list[list[str]] = []
    verdicts = {k: _verdicts(m) for k, m in results.items()}

    def row(label: str, goal: str, key: str, cell: Any) -> None:
        rows.append(
            [
                label,
                *(cell(results[k]) for k in keys),
                goal,
                ", ".join(_ok(verdicts[k][key]) for k in keys) if key else "-",
            ]
        )

    row(
        "Sync loop rate, healthy seconds (per bus)",
        "≥ 49 Hz (2 % of 50)",
        "loop",
        lambda m: ", ".join(f"{hz:.1f} Hz" for hz in m["loop_hz"].values()),
    )
    row(
        "Motor updates, healthy seconds (slowest motor / mean)",
        "≥ 49 Hz",
        "motor",
        lambda m: (
            f"{min(m['motor_hz'].values()):.1f} / {statistics.fmean(m['motor_hz'].values()):.1f} Hz"
        ),
    )
    row("Unplugged motor marked offline", "< 0.5 s", "offline", lambda m: _fmt_s(m["offline_s"]))
    row(
        "Lost bus: all its motors offline",
        "< 0.5 s",
        "bus_offline",
        lambda m: _fmt_s(m["bus_offline_s"]),
    )
    row("Replugged motor online again", "< 1.5 s", "back", lambda m: _fmt_s(m["back_s"]))
    row("Bus back: all its motors online", "< 1.5 s", "bus_back", lambda m: _fmt_s(m["bus_back_s"]))
    row(
        "Goal writes lost while online (checked)",
        "0",
        "writes",
        lambda m: f"{m['goal_checks']['lost']} ({m['goal_checks']['checked']})",
    )
    row("Motors marked offline with no fault", "-", "", lambda m: str(m["spurious_offline"]))
    row(
        "RSS start → end",
        "< +10 %",
        "rss",
        lambda m: f"{m['start']['VmRSS'] / 1024:.1f} → {m['end']['VmRSS'] / 1024:.1f} MB",
    )
    row(
        "Threads start → end",
        "equal",
        "threads",
        lambda m: f"{m['start']['Threads']} → {m['end']['Threads']}",
    )
    row(
        "Threads alive at the end (sync, primitive)",
        "all",
        "alive",
        lambda m: (
            f"{sum(m['alive']['sync'].values())}/{len(m['alive']['sync'])}, "
            f"{'yes' if m['alive']['primitive'] else 'no'}"
        ),
    )
    row("robot.close()", "< 1 s", "close", lambda m: f"{m['close_s'] * 1000:.0f} ms")
    passed = all(all(v.values()) for v in verdicts.values())
    headers = ["poppy", *(results[k]["label"] for k in keys), "Goal", "Met"]
    return Table("poppy under faults", headers, rows), passed


def _pypot_table(results: dict[str, dict[str, Any]]) -> Table:
    keys = list(results)

    def cells(m: dict[str, Any]) -> list[str]:
        if "error" in m:
            return [m["error"]] + ["-"] * 6
        alive = m["alive"]
        return [
            ", ".join(f"{hz:.1f} Hz" for hz in m["loop_hz_before_loss"].values()),
            ", ".join(f"{hz:.1f} Hz" for hz in m["loop_hz_after_loss"].values()),
            ", ".join(str(n) for n in m["loop_errors"].values()),
            f"{sum(alive['sync'].values())}/{len(alive['sync'])}, "
            f"{'yes' if alive['primitive'] else 'no'}",
            f"{m['start']['VmRSS'] / 1024:.1f} → {m['end']['VmRSS'] / 1024:.1f} MB",
            f"{m['start']['Threads']} → {m['end']['Threads']}",
            "-" if m["close_s"] is None else f"{m['close_s'] * 1000:.0f} ms",
        ]

    labels = [
        "Sync loop rate before its bus was first lost (per bus)",
        "Sync loop rate after its bus came back",
        "Loop runs that raised",
        "Threads alive at the end (sync loops, primitive)",
        "RSS start → end",
        "Threads start → end",
        "robot.close()",
    ]
    columns = [cells(results[k]) for k in keys]
    rows = [[label, *(c[i] for c in columns)] for i, label in enumerate(labels)]
    headers = ["pypot", *(results[k]["label"] for k in keys)]
    return Table("pypot on the same faults", headers, rows)


def _torque_lost(record: Any) -> str:
    if not isinstance(record, dict) or record.get("error"):
        return str(record.get("error") if isinstance(record, dict) else record)
    return f"{record['lost']} of {record['writes']}"


def _control_clean(control: Any) -> bool:
    """The control run (no output flush) lost no write and failed no read."""
    return (
        isinstance(control, dict)
        and not control.get("error")
        and control["lost"] == 0
        and control["reads_failed"] == 0
    )


def torque_met(torque: dict[str, Any]) -> bool:
    """The emulator loses no write (the control run, without the client's output flush)."""
    controls = [r.get("control") for r in torque.values() if isinstance(r, dict)]
    return bool(controls) and all(_control_clean(c) for c in controls)


def _torque_table(torque: dict[str, Any]) -> Table:
    rows = []
    for target, record in torque.items():
        if not isinstance(record, dict) or record.get("error"):
            rows.append([target, _torque_lost(record), "-", "-", "-", "-", "-"])
            continue
        load = record.get("load_1min", ["?", "?"])
        control = record.get("control")
        rows.append(
            [
                target,
                f"{_torque_lost(record)} (reads failed: {record['reads_failed']})",
                _torque_lost(control) if control is not None else "-",
                f"{record['elapsed_s']:.1f} s",
                f"{load[0]} → {load[1]}",
                "0",
                "yes" if _control_clean(control) else "**no**",
            ]
        )
    headers = [
        "Emulator",
        "Writes lost, pypot as is",
        "Writes lost, output flush skipped",
        "Time (as is)",
        "Load (1 min avg)",
        "Goal (the emulator's losses)",
        "Met",
    ]
    return Table(
        "pypot Dxl320IO toggling the Ergo Jr's torque (flushes before every packet)", headers, rows
    )


def build_result(raw: dict[str, Any]) -> BenchResult:
    """Tables, verdict and notes of the soak from its raw records."""
    poppy: dict[str, dict[str, Any]] = {}
    pypot: dict[str, dict[str, Any]] = {}
    failures: list[str] = []
    for key, robot in raw["robots"].items():
        for peer, run in robot["runs"].items():
            record = run["record"]
            events = [FaultEvent(**e) for e in run["events"]]
            if record.get("error"):
                failures.append(f"{peer} on {robot['label']}: {record['error']}")
                if peer == "pypot":
                    pypot[key] = {"label": robot["label"], "error": str(record["error"])}
                continue
            metrics = (poppy_metrics if peer == "poppy" else pypot_metrics)(record, events)
            metrics["label"] = robot["label"]
            (poppy if peer == "poppy" else pypot)[key] = metrics
    plan = raw["plan"]
    faults = Table(
        "Faults injected (per robot and client)",
        ["Robot", "Minutes", "Unplugs", "Bus losses", "Reply bytes corrupted", "Replies lost"],
        [
            [
                m["label"],
                f"{m['duration_s'] / 60:.1f}",
                str(m["unplugs"]),
                str(m["losses"]),
                f"{plan['corrupt']:.0%}",
                f"{plan['drop']:.0%}",
            ]
            for m in poppy.values()
        ],
    )
    tables = [faults]
    passed: bool | None = False
    if poppy:
        table, passed = _poppy_table(poppy)
        tables.append(table)
    if pypot:
        tables.append(_pypot_table(pypot))
    if raw.get("torque"):
        tables.append(_torque_table(raw["torque"]))
        passed = bool(passed) and torque_met(raw["torque"])
    if failures:
        passed = False
    unplug, lose = plan["unplug"], plan["lose"]
    intro = (
        f"Each robot runs {raw['minutes']:g} minutes per client on `poppy emulate --profile NAME "
        f"--wire-timing --latency-ms {plan['latency_ms']:g} --control --link ...` (its own "
        "process; one pty per bus behind a symlink, as `/dev/serial/by-id`), with its sync "
        "loops at 50 Hz and a `Sinus` primitive moving every motor. Faults go in through the "
        f"emulator's stdin once the robot is built: {plan['corrupt']:.0%} of reply bytes "
        f"corrupted, {plan['drop']:.0%} of replies dropped, one motor unplugged for "
        f"{unplug[2]:g} s every {unplug[1]:g} s (from {unplug[0]:g} s), one bus lost for "
        f"{lose[2]:g} s every {lose[1]:g} s (from {lose[0]:g} s). Rates are judged on whole "
        f"seconds from {MARGIN_BEFORE_S:g} s before a fault to {MARGIN_AFTER_S:g} s after it. "
        "pypot runs the same schedule on a fresh emulator, from the same JSON config "
        "(`bench/peers/pypot_soak.py`)."
    )
    notes = [
        f"Machine load (1-minute average) at start and end of the soak: "
        f"{raw['load_1min'][0]} → {raw['load_1min'][1]}"
        + (
            "; the machine was shared with other work, which delays the emulator and the clients."
            if max(raw["load_1min"]) > 1.0
            else " (otherwise idle)."
        ),
        "Recovery times are measured from the moment the fault command was written to the "
        "emulator to the moment the client saw the flag change (polled every 2 ms, one "
        "monotonic clock for all processes). Goal writes are checked once a second on every "
        "motor online for at least 1 s: its goal register, read back under the bus lock, "
        "must hold the last goal the sync loop wrote to it. A wrong value is read twice more: "
        "protocol 1's 8-bit checksum lets a few garbled replies through (two flipped bits that "
        "cancel out), which a second read shows; such misreads are counted apart "
        f"({', '.join(str(m['goal_checks'].get('misread', 0)) for m in poppy.values())}).",
        "Writes lost by a client that flushes before every packet happen in the kernel, not in "
        "the emulator: Linux hands bytes written to a pty slave to the master side in a "
        "deferred worker, and a flush of the slave's output that comes before that worker ran "
        "discards them before any reader can see them (see docs/emulator.md). The control run "
        "is the same client with only that output flush skipped: what it loses is what the "
        "emulator loses (the goal). The kernel's share grows with the client's speed and with "
        "what else runs (MuJoCo's physics thread in `poppy sim`); on a real USB adapter the "
        "bytes leave at once.",
    ]
    notes += [f"Failed: {f}" for f in failures]
    if raw.get("peers_note"):
        notes.append(f"Peers: {raw['peers_note']}")
    return BenchResult(
        name="soak",
        title="Fault soak",
        intro=intro,
        tables=tables,
        notes=notes,
        passed=passed,
        raw=raw,
    )
