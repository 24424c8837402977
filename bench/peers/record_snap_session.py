"""Replay the Snap! session of tests/server/data/snap_session.json on a Snap! server; record it.

Standard library only: run it with any Python, pointed at pypot's Snap! server
(``bench/peers/pypot_snap.py`` over ``poppy emulate --profile ergo-jr``)::

    python bench/peers/record_snap_session.py --url http://127.0.0.1:6970 --write

Each step gets ``pypot: {"status", "text"}`` (an HTML error page is kept as its status only).
Without ``--write`` the answers are printed.
"""

from __future__ import annotations

import argparse
import json
import time
import urllib.error
import urllib.request
from pathlib import Path

SESSION = Path(__file__).resolve().parents[2] / "tests" / "server" / "data" / "snap_session.json"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--url", required=True)
    parser.add_argument("--write", action="store_true")
    args = parser.parse_args()
    data = json.loads(SESSION.read_text())
    for step in data["steps"]:
        try:
            with urllib.request.urlopen(args.url + step["path"], timeout=10) as answer:
                status, text = answer.status, answer.read().decode()
        except urllib.error.HTTPError as exc:
            status, text = exc.code, None
        step["pypot"] = {"status": status, "text": text}
        print(f"{step['path']} -> {status} {text!r}")
        time.sleep(step["after_s"])
    if args.write:
        SESSION.write_text(json.dumps(data, indent=1, ensure_ascii=False) + "\n")


if __name__ == "__main__":
    main()
