"""The dataset's parquet tables (frames, episodes, tasks) and JSON files, written atomically.

Facts from LeRobot 0.4.4: a frame row holds the non-video features (vectors as fixed-size
lists); meta/tasks.parquet is pandas' ``DataFrame({"task_index": ...}, index=tasks)`` as
``to_parquet`` stores it (the tasks in the index column ``__index_level_0__`` and pandas'
schema metadata naming it), which ``pd.read_parquet`` turns back into the index.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from poppy_core.errors import FileError
from poppy_core.files import write_file

TASK_INDEX_COLUMN = "__index_level_0__"


def write_json(path: Path, data: dict[str, Any]) -> None:
    """JSON as LeRobot writes it (indent 4, UTF-8), replacing the file atomically."""
    text = json.dumps(data, indent=4, ensure_ascii=False)
    write_file(path, text, replace=True, make_folder=True)


def read_json(path: Path) -> dict[str, Any]:
    """A JSON object from ``path`` (FileError when missing or not an object)."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise FileError(f"{path} is missing: is this a dataset folder?", path=str(path)) from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise FileError(f"{path} cannot be read: {exc}", path=str(path)) from None
    if not isinstance(data, dict):
        raise FileError(f"{path} does not hold a JSON object", path=str(path))
    return data


def write_table(path: Path, table: pa.Table, *, replace: bool = True) -> None:
    """A parquet file (snappy, as LeRobot's writer) put in place atomically."""
    sink = pa.BufferOutputStream()
    pq.write_table(table, sink, compression="snappy")
    write_file(path, sink.getvalue().to_pybytes(), replace=replace, make_folder=True)


def read_table(path: Path) -> pa.Table:
    """A parquet file as an arrow table (FileError when unreadable)."""
    try:
        return pq.read_table(path)
    except FileNotFoundError:
        raise FileError(f"{path} is missing", path=str(path)) from None
    except (OSError, pa.ArrowException) as exc:
        raise FileError(f"{path} cannot be read: {exc}", path=str(path)) from None


def frames_table(columns: dict[str, Any], features: dict[str, Any]) -> pa.Table:
    """One episode's frames: a column per non-video feature, in the features' order."""
    arrays: dict[str, pa.Array] = {}
    for key, feature in features.items():
        if feature["dtype"] in ("video", "image"):
            continue
        kind = pa.float32() if feature["dtype"] == "float32" else pa.int64()
        values = columns[key]
        if feature["shape"] == [1]:  # a scalar column, as LeRobot stores shape (1,) features
            arrays[key] = pa.array(np.asarray(values).reshape(-1), type=kind)
        else:
            size = int(feature["shape"][0])
            flat = pa.array(values.reshape(-1), type=kind)
            arrays[key] = pa.FixedSizeListArray.from_arrays(flat, size)
    return pa.table(arrays)


def tasks_table(tasks: list[str]) -> pa.Table:
    """meta/tasks.parquet: the tasks as pandas' index, ``task_index`` their number."""
    table = pa.table(
        {
            "task_index": pa.array(range(len(tasks)), type=pa.int64()),
            TASK_INDEX_COLUMN: pa.array(tasks, type=pa.string()),
        }
    )
    pandas_meta = {
        "index_columns": [TASK_INDEX_COLUMN],
        "column_indexes": [
            {
                "name": None,
                "field_name": None,
                "pandas_type": "unicode",
                "numpy_type": "object",
                "metadata": {"encoding": "UTF-8"},
            }
        ],
        "columns": [
            {
                "name": "task_index",
                "field_name": "task_index",
                "pandas_type": "int64",
                "numpy_type": "int64",
                "metadata": None,
            },
            {
                "name": None,
                "field_name": TASK_INDEX_COLUMN,
                "pandas_type": "unicode",
                "numpy_type": "object",
                "metadata": None,
            },
        ],
        "creator": {"library": "pyarrow", "version": pa.__version__},
    }
    return table.replace_schema_metadata({b"pandas": json.dumps(pandas_meta).encode()})


def read_tasks(path: Path) -> list[str]:
    """The tasks in task_index order."""
    table = read_table(path)
    indices = table["task_index"].to_pylist()
    rows = sorted(zip(indices, table[TASK_INDEX_COLUMN].to_pylist(), strict=True))
    return [str(task) for _, task in rows]


def episodes_table(rows: list[dict[str, Any]]) -> pa.Table:
    """meta/episodes/chunk-000/file-000.parquet: one row per episode."""
    return pa.Table.from_pylist(rows)


def read_episodes(path: Path) -> list[dict[str, Any]]:
    """The episode rows, in episode order."""
    rows: list[dict[str, Any]] = read_table(path).to_pylist()
    return sorted(rows, key=lambda row: int(row["episode_index"]))
