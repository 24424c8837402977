"""Load a move JSON file with pypot's own ``Move.load`` and print one JSON result line.

Run it with the peers venv: ``bench/.venv-peers/bin/python bench/peers/pypot_move_load.py
--file /tmp/long.json --repeat 3``.
"""

from __future__ import annotations

import argparse
import importlib
import sys
import time
from typing import Any

from _common import emit


def run(path: str, repeat: int) -> dict[str, Any]:
    """Load ``path`` ``repeat`` times with ``pypot.primitive.move.Move.load``.

    Args:
        path: the move JSON file.
        repeat: how many loads to time.

    Returns:
        The JSON-ready result; ``error`` is None on success.
    """
    record: dict[str, Any] = {
        "peer": "pypot",
        "file": path,
        "import_s": None,
        "load_s": [],
        "frames": None,
        "motors": None,
        "error": None,
    }
    start = time.perf_counter()
    try:
        pypot = importlib.import_module("pypot")
        move_module = importlib.import_module("pypot.primitive.move")
    except ImportError as exc:
        record["error"] = f"import failed: {exc}"
        return record
    record["import_s"] = time.perf_counter() - start
    record["version"] = str(pypot.__version__)
    for _ in range(repeat):
        start = time.perf_counter()
        try:
            with open(path) as handle:
                move = move_module.Move.load(handle)
        except Exception as exc:  # pypot raises whatever json or its KDTreeDict raise
            record["error"] = f"load failed: {type(exc).__name__}: {exc}"
            return record
        record["load_s"].append(time.perf_counter() - start)
    positions = move.positions()
    record["frames"] = len(positions)
    first = next(iter(dict.values(positions)), {})
    record["motors"] = len(first)
    return record


def main(argv: list[str] | None = None) -> int:
    """Parse the command line, load the file, print the JSON line.

    Args:
        argv: Arguments; ``sys.argv[1:]`` when None.

    Returns:
        0 on success, 1 if the file could not be loaded.
    """
    parser = argparse.ArgumentParser(description="pypot Move.load timing")
    parser.add_argument("--file", required=True, help="a pypot move JSON file")
    parser.add_argument("--repeat", type=int, default=3, help="loads to time (default 3)")
    args = parser.parse_args(argv)
    record = run(args.file, max(1, args.repeat))
    emit(record)
    return 0 if record["error"] is None else 1


if __name__ == "__main__":
    sys.exit(main())
