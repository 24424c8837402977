"""Remove an episode from a dataset, renumbering the rest, all at once or not at all.

The new dataset is built in a hidden folder beside the old one (unchanged files hard-linked,
renumbered data files rewritten, videos renamed one place down), then swapped in with one
rename (``renameat2(RENAME_EXCHANGE)`` on Linux; elsewhere two renames). Until the swap the
dataset is untouched; a run killed before it leaves only the hidden folder, which the next
run removes. A dataset packing several episodes a file (LeRobot's own writer) is rebuilt by
``delete_packed``; poppy's own (an episode a file) keeps that layout, the files moved down.
"""

from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import errno
import os
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pyarrow as pa

from poppy_core.dataset import feature_stats as stats
from poppy_core.dataset import layout, tables
from poppy_core.dataset.delete_packed import rebuild_packed
from poppy_core.dataset.rows import data_path, episode_rows, find_episode, stats_of_row
from poppy_core.errors import ArgumentError, FileError

RENAME_EXCHANGE = 2
AT_FDCWD = -100
RENUMBERED = ("episode_index", "index", "task_index")


@dataclass(frozen=True)
class EpisodeDeleted:
    """What a deletion did."""

    episode: int
    frames: int
    episodes_left: int
    frames_left: int
    tasks_left: int


def delete_episode(root: Path, episode: int) -> EpisodeDeleted:
    """Remove ``episode`` from the dataset in ``root``; later episodes move one place down."""
    root = Path(root).expanduser().resolve()
    info = tables.read_json(root / layout.INFO_PATH)
    if info.get("codebase_version") != layout.CODEBASE_VERSION:
        raise ArgumentError(
            f"{root} is a LeRobot dataset {info.get('codebase_version')}, not "
            f"{layout.CODEBASE_VERSION}",
            field="root",
        )
    rows = episode_rows(root)
    gone = find_episode(rows, episode)
    if len(rows) == 1:
        raise ArgumentError(
            f"episode {episode} is the only one: delete the folder {root} instead",
            field="episode",
        )
    video_keys = [k for k, ft in info.get("features", {}).items() if ft.get("dtype") == "video"]
    packed = _packs_episodes(rows, video_keys)
    for stale in root.parent.glob(f".{root.name}.delete-*"):
        shutil.rmtree(stale, ignore_errors=True)
    work = root.parent / f".{root.name}.delete-{os.getpid()}"
    try:
        shutil.copytree(root, work, symlinks=True, copy_function=_link_or_copy)
        kept = _rebuild(root, work, info, rows, episode, video_keys, packed)
        _swap(work, root)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return EpisodeDeleted(
        episode,
        int(gone["length"]),
        len(kept),
        sum(int(row["length"]) for row in kept),
        len({task for row in kept for task in row.get("tasks") or ()}),
    )


def _rebuild(
    root: Path,
    work: Path,
    info: dict[str, Any],
    rows: list[dict[str, Any]],
    episode: int,
    video_keys: list[str],
    packed: bool,
) -> list[dict[str, Any]]:
    """Write the dataset without ``episode`` into ``work`` (a linked copy of ``root``)."""
    old_tasks = tables.read_tasks(root / layout.TASKS_PATH)
    kept = [dict(row) for row in rows if int(row["episode_index"]) != episode]
    used = {task for row in kept for task in row.get("tasks") or ()}
    tasks = [task for task in old_tasks if task in used]
    task_map = {old_tasks.index(task): new for new, task in enumerate(tasks)}
    if packed:
        kept, episode_stats, start = rebuild_packed(
            root, work, rows, episode, task_map, _video, video_keys
        )
    else:
        episode_stats, start = _move_down(root, work, rows, kept, episode, task_map, video_keys)
    _write_meta(work, info, kept, tasks, episode_stats, start)
    return kept


def _move_down(
    root: Path,
    work: Path,
    rows: list[dict[str, Any]],
    kept: list[dict[str, Any]],
    episode: int,
    task_map: dict[int, int],
    video_keys: list[str],
) -> tuple[list[dict[str, stats.Stats]], int]:
    """poppy's layout (an episode a file): the later episodes' files move one place down."""
    for row in rows:
        if int(row["episode_index"]) == episode:
            _unlink(data_path(work, row))
            for key in video_keys:
                _unlink(work / _video(row, key))
    start = 0
    episode_stats: list[dict[str, stats.Stats]] = []
    for position, row in enumerate(kept):
        source = data_path(root, row)
        old_data = data_path(work, row)
        old_video = {key: _video(row, key) for key in video_keys}
        chunk, file = layout.chunk_and_file(position)
        length = int(row["length"])
        moved = position != int(row["episode_index"]) or int(row["dataset_from_index"]) != start
        row.update(
            {
                "episode_index": position,
                "data/chunk_index": chunk,
                "data/file_index": file,
                "dataset_from_index": start,
                "dataset_to_index": start + length,
            }
        )
        for key in video_keys:
            row[f"videos/{key}/chunk_index"] = chunk
            row[f"videos/{key}/file_index"] = file
        if moved or task_map != {i: i for i in task_map}:
            frames = _renumbered(tables.read_table(source), position, start, task_map)
            _unlink(old_data)
            tables.write_table(data_path(work, row), frames)
            for name in RENUMBERED:
                values = frames[name].to_numpy()
                for stat, value in stats.vector_stats(values).items():
                    row[f"stats/{name}/{stat}"] = value.tolist()
            for key in video_keys:
                target = work / _video(row, key)
                if target != work / old_video[key]:
                    target.parent.mkdir(parents=True, exist_ok=True)
                    os.replace(work / old_video[key], target)
        episode_stats.append(stats_of_row(row))
        start += length
    return episode_stats, start


def _write_meta(
    work: Path,
    info: dict[str, Any],
    kept: list[dict[str, Any]],
    tasks: list[str],
    episode_stats: list[dict[str, stats.Stats]],
    start: int,
) -> None:
    """Tasks, the episodes table, stats.json and info.json of the dataset left."""
    tables.write_table(work / layout.TASKS_PATH, tables.tasks_table(tasks))
    for path in (work / layout.EPISODES_DIR).glob("*/*.parquet"):
        path.unlink()
    episodes_path = work / layout.EPISODES_PATH.format(chunk_index=0, file_index=0)
    for row in kept:
        row["meta/episodes/chunk_index"] = 0
        row["meta/episodes/file_index"] = 0
    tables.write_table(episodes_path, tables.episodes_table(kept))
    merged = stats.aggregate_all(episode_stats)
    tables.write_json(work / layout.STATS_PATH, stats.to_json(merged))
    info.update(
        total_episodes=len(kept),
        total_frames=start,
        total_tasks=len(tasks),
        splits={"train": f"0:{len(kept)}"},
    )
    tables.write_json(work / layout.INFO_PATH, info)


def _renumbered(frames: pa.Table, episode: int, start: int, task_map: dict[int, int]) -> pa.Table:
    """An episode's frames with its new episode number, dataset indices and task numbers."""
    length = frames.num_rows
    columns = {
        "episode_index": pa.array([episode] * length, type=pa.int64()),
        "index": pa.array(range(start, start + length), type=pa.int64()),
        "task_index": pa.array(
            [task_map[int(t)] for t in frames["task_index"].to_pylist()], type=pa.int64()
        ),
    }
    for name, array in columns.items():
        frames = frames.set_column(frames.schema.get_field_index(name), name, array)
    return frames


def _packs_episodes(rows: list[dict[str, Any]], video_keys: list[str]) -> bool:
    """True when a data or video file holds several episodes (LeRobot's writer lays them so)."""
    places: list[list[Path]] = [[data_path(Path(), row) for row in rows]]
    places += [[_video(row, key) for row in rows] for key in video_keys]
    return any(len(set(paths)) != len(paths) for paths in places)


def _video(row: dict[str, Any], key: str) -> Path:
    return Path(
        layout.VIDEO_PATH.format(
            video_key=key,
            chunk_index=int(row[f"videos/{key}/chunk_index"]),
            file_index=int(row[f"videos/{key}/file_index"]),
        )
    )


def _unlink(path: Path) -> None:
    with contextlib.suppress(FileNotFoundError):
        path.unlink()


def _link_or_copy(source: str, target: str) -> None:
    try:
        os.link(source, target)
    except OSError:
        shutil.copy2(source, target)


def _swap(new: Path, root: Path) -> None:
    """Put ``new`` in the place of ``root`` (whose old content ends up in ``new``)."""
    if _exchange(new, root):
        return
    old = root.parent / f".{root.name}.old-{os.getpid()}"
    try:
        os.rename(root, old)
    except OSError as exc:
        raise FileError(f"cannot replace {root}: {exc.strerror}", path=str(root)) from None
    try:
        os.rename(new, root)
    except BaseException:
        os.rename(old, root)  # the dataset back in its place, as it was
        raise
    os.rename(old, new)


def _exchange(a: Path, b: Path) -> bool:
    """Swap two folders atomically with Linux's renameat2; False where it is not available."""
    name = ctypes.util.find_library("c")
    if name is None:
        return False
    libc = ctypes.CDLL(name, use_errno=True)
    call = getattr(libc, "renameat2", None)
    if call is None:
        return False
    done = call(AT_FDCWD, os.fsencode(a), AT_FDCWD, os.fsencode(b), RENAME_EXCHANGE)
    if done == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP):
        return False
    raise FileError(f"cannot replace {b}: {os.strerror(code)}", path=str(b))
