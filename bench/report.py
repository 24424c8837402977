"""Save benchmark results as JSON (bench/results/) and render docs/performance.md from them."""

from __future__ import annotations

import dataclasses
import json
import re
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
only), `--list`. The peers live in their own venv, `bench/.venv-peers`, built by
`bench/setup_peers.sh` on first use (see `bench/README.md`); without it the benchmarks still
run and say that the peers were not measured. Each run rewrites this file from the latest
result of the benchmarks it ran (the sections of the others stay as they were) and keeps the
raw measurements in `bench/results/NAME.json` (git-ignored) and a time-stamped copy next to it.
"""

_SECTION_NAME = re.compile(r"`python -m bench ([\w-]+)`")


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


def existing_sections(path: Path) -> dict[str, str]:
    """The benchmark sections of an existing report, keyed by benchmark name."""
    try:
        text = path.read_text()
    except OSError:
        return {}
    sections: dict[str, str] = {}
    for chunk in re.split(r"\n(?=## )", text):
        match = _SECTION_NAME.search(chunk) if chunk.startswith("## ") else None
        if match and not chunk.startswith("## Machine"):
            sections[match.group(1)] = chunk.strip()
    return sections


def write_doc(names: Iterable[str], path: Path = DOC_PATH) -> Path:
    """Render docs/performance.md from the latest saved result of each benchmark.

    A benchmark with no saved result here keeps the section the report already had, so a run
    of one benchmark on a fresh clone does not drop the others' figures.

    Args:
        names: the registered benchmarks, in report order (those never run are left out).
        path: where to write.

    Returns:
        The path written.
    """
    kept = existing_sections(path)
    parts = [DOC_INTRO.rstrip()]
    sections: list[str] = []
    machines: list[dict[str, Any]] = []
    for name in names:
        loaded = load_result(name)
        if loaded is not None:
            result, machine = loaded
            machines.append(machine)
            sections.append(render_section(result, machine))
        elif name in kept:
            sections.append(kept[name])
    if machines:
        parts.append(_machine_block(max(machines, key=lambda m: str(m["date"]))))
    elif kept and (machine_block := _kept_machine_block(path)):
        parts.append(machine_block)
    parts += sections
    path.write_text("\n\n".join(parts) + "\n")
    return path


def _kept_machine_block(path: Path) -> str | None:
    try:
        text = path.read_text()
    except OSError:
        return None
    match = re.search(r"^## Machine\n.*?(?=\n## |\Z)", text, flags=re.S | re.M)
    return match.group(0).strip() if match else None
