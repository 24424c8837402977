"""Save benchmark results as JSON (bench/results/) and render docs/performance.md from them."""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from bench.registry import REPO_ROOT, RESULTS_DIR, BenchResult, Table

DOC_PATH = REPO_ROOT / "docs" / "performance.md"

DOC_INTRO = """\
# Performance

How fast poppy is on the bus, measured side by side with its peers, **pypot** (the Poppy
project's previous library) and the Robotis **dynamixel-sdk**, on the same emulated buses in
the same run. Goals come from the project's issues; each table says whether they are met.

Run everything with `make bench` (it runs `.venv/bin/python -m bench`), or one benchmark with
`.venv/bin/python -m bench scan`. Options: `--repeat N` (default 3), `--no-peers` (poppy
only), `--list`, `--minutes M` (the soak's length per robot and client, default 10),
`--baseline DIR` (`scan`, `emulator`, `server` and `camera` also measure the poppy of another
checkout, e.g. `git worktree add /tmp/old REV`, alternately with this one in every round: on a
loaded machine only figures taken side by side compare). The fault
soak takes about 45 minutes: it runs only when named (`python -m bench soak`). The peers live
in their own venv, `bench/.venv-peers`, built by `bench/setup_peers.sh` on first use (see
`bench/README.md`); without it the benchmarks still run and say that the peers were not
measured. Each run rewrites the sections of the benchmarks it ran from their latest results
(the others are kept) and keeps the raw measurements in `bench/results/NAME.json`
(git-ignored) and a time-stamped copy next to it.
"""


def _stamp(date: str) -> str:
    return date.replace(":", "").replace("-", "").replace("+0000", "Z")


def save_result(result: BenchResult, machine: dict[str, Any]) -> Path:
    """Write a result to ``bench/results/NAME.json`` and a time-stamped copy.

    Args:
        result: the benchmark result.
        machine: ``machine_info()`` of the run.

    Returns:
        The path of ``NAME.json``.
    """
    RESULTS_DIR.mkdir(parents=True, exist_ok=True)
    text = json.dumps({"machine": machine, "result": dataclasses.asdict(result)}, indent=1)
    latest = RESULTS_DIR / f"{result.name}.json"
    latest.write_text(text + "\n")
    (RESULTS_DIR / f"{result.name}-{_stamp(machine['date'])}.json").write_text(text + "\n")
    return latest


def load_result(name: str) -> tuple[BenchResult, dict[str, Any]] | None:
    """Read ``bench/results/NAME.json`` back (None when absent or unreadable)."""
    path = RESULTS_DIR / f"{name}.json"
    try:
        data = json.loads(path.read_text())
        fields = dict(data["result"])
        fields["tables"] = [Table(**t) for t in fields["tables"]]
        return BenchResult(**fields), data["machine"]
    except (OSError, ValueError, KeyError, TypeError):
        return None


def _escape(cell: str) -> str:
    return cell.replace("|", "\\|").replace("\n", " ")


def render_table(table: Table) -> str:
    """A Markdown table with a bold title line."""
    lines = [f"**{table.title}**", ""]
    lines.append("| " + " | ".join(map(_escape, table.headers)) + " |")
    lines.append("|" + "|".join(" --- " for _ in table.headers) + "|")
    lines += ["| " + " | ".join(map(_escape, row)) + " |" for row in table.rows]
    return "\n".join(lines)


def _machine_block(machine: dict[str, Any]) -> str:
    peers = machine.get("peers_python") or "not available"
    return "\n".join(
        [
            "## Machine",
            "",
            f"- CPU: {machine['cpu']}, {machine['cores']} logical cores",
            f"- OS: {machine['os']}",
            f"- Python: {machine['python']} (poppy), {peers} (peers venv)",
            f"- Date: {machine['date']}",
        ]
    )


def render_section(result: BenchResult, machine: dict[str, Any]) -> str:
    """One benchmark's section: verdict, intro, tables, notes."""
    verdict = {True: "all goals met", False: "goals missed", None: "no goal"}[result.passed]
    parts = [
        f"## {result.title} — {verdict}",
        f"Measured {machine['date']} (`python -m bench {result.name}`).",
        result.intro,
        *(render_table(t) for t in result.tables),
    ]
    if result.notes:
        parts.append("### Notes")
        parts += result.notes
    return "\n\n".join(parts)


def _existing_sections(path: Path) -> list[tuple[str, str]]:
    """(title, text) of each ``## `` section of the current file (``Machine`` included)."""
    try:
        text = path.read_text()
    except OSError:
        return []
    sections: list[tuple[str, str]] = []
    for chunk in text.split("\n## ")[1:]:
        title = chunk.splitlines()[0].split(" — ")[0].strip()
        sections.append((title, "## " + chunk.rstrip()))
    return sections


def write_doc(names: Iterable[str], path: Path = DOC_PATH) -> Path:
    """Render docs/performance.md from the latest saved result of each benchmark.

    A section of the current file whose benchmark has no saved result here (it was measured
    on another machine or checkout) is kept as it is, in its place.

    Args:
        names: the registered benchmarks, in report order (those never run are left out).
        path: where to write.

    Returns:
        The path written.
    """
    loaded = [r for r in (load_result(n) for n in names) if r is not None]
    fresh = {result.title: render_section(result, machine) for result, machine in loaded}
    if loaded:
        newest = max((m for _, m in loaded), key=lambda m: str(m["date"]))
        fresh["Machine"] = _machine_block(newest)
    parts = [DOC_INTRO.rstrip()]
    kept = _existing_sections(path)
    if "Machine" in fresh and all(title != "Machine" for title, _ in kept):
        parts.append(fresh.pop("Machine"))
    for title, text in kept:
        parts.append(fresh.pop(title, text))
    parts += list(fresh.values())
    path.write_text("\n\n".join(parts) + "\n")
    return path
