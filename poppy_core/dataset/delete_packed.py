"""An episode removed from a dataset packing several episodes a file (LeRobot's own writer).

The data files that hold it are rewritten without its frames, the later frames renumbered
(``episode_index``, ``index``, ``task_index``); a file left empty is removed. The videos are
kept as they are: each episode names its span of the file (``from_timestamp``,
``to_timestamp``), so the removed episode's span is simply no longer named; a video file that
only it used is removed. ``delete.delete_episode`` builds this in its hidden folder and swaps
it in, as for poppy's own layout.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from poppy_core.dataset import feature_stats as stats
from poppy_core.dataset import tables
from poppy_core.dataset.rows import data_path, stats_of_row

RENUMBERED = ("episode_index", "index", "task_index")


def rebuild_packed(
    root: Path,
    work: Path,
    rows: list[dict[str, Any]],
    episode: int,
    task_map: dict[int, int],
    video_of: Any,
    video_keys: list[str],
) -> tuple[list[dict[str, Any]], list[dict[str, stats.Stats]], int]:
    """Write the data files without ``episode`` into ``work``; the kept rows (renumbered), their
    stats and the frames left."""
    gone = next(row for row in rows if int(row["episode_index"]) == episode)
    gone_from, gone_to = int(gone["dataset_from_index"]), int(gone["dataset_to_index"])
    removed = gone_to - gone_from
    kept = [dict(row) for row in rows if int(row["episode_index"]) != episode]
    new_number = {int(row["episode_index"]): position for position, row in enumerate(kept)}
    for path in sorted({data_path(Path(), row) for row in rows}):
        _rewrite(root / path, work / path, episode, removed, gone_to, new_number, task_map)
    named = {video_of(row, key) for row in kept for key in video_keys}
    for key in video_keys:
        only_gone = video_of(gone, key)
        if only_gone not in named:
            (work / only_gone).unlink(missing_ok=True)
    tables_read: dict[Path, pa.Table] = {}
    episode_stats: list[dict[str, stats.Stats]] = []
    start = 0
    for position, row in enumerate(kept):
        length = int(row["length"])
        row.update(
            {
                "episode_index": position,
                "dataset_from_index": start,
                "dataset_to_index": start + length,
            }
        )
        path = work / data_path(Path(), row)
        if path not in tables_read:
            tables_read[path] = tables.read_table(path)
        table = tables_read[path]
        mine = table.filter(pc.equal(table["episode_index"], position))
        for name in RENUMBERED:
            values = mine[name].to_numpy()
            for stat, value in stats.vector_stats(values).items():
                row[f"stats/{name}/{stat}"] = value.tolist()
        episode_stats.append(stats_of_row(row))
        start += length
    return kept, episode_stats, start


def _rewrite(
    source: Path,
    target: Path,
    episode: int,
    removed: int,
    gone_to: int,
    new_number: dict[int, int],
    task_map: dict[int, int],
) -> None:
    """One data file without ``episode``'s frames, the others renumbered (removed if empty)."""
    table = tables.read_table(source)
    table = table.filter(pc.not_equal(table["episode_index"], episode))
    target.unlink(missing_ok=True)  # a hard link to the old file: never written through
    if table.num_rows == 0:
        return
    episodes = table["episode_index"].to_numpy()
    index = table["index"].to_numpy()
    columns = {
        "episode_index": np.array([new_number[int(e)] for e in episodes], dtype=np.int64),
        "index": np.where(index >= gone_to, index - removed, index).astype(np.int64),
        "task_index": np.array(
            [task_map[int(t)] for t in table["task_index"].to_numpy()], dtype=np.int64
        ),
    }
    for name, values in columns.items():
        field = table.schema.get_field_index(name)
        table = table.set_column(field, name, pa.array(values, type=pa.int64()))
    tables.write_table(target, table)
