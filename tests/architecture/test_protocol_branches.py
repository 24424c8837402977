"""Code asks the protocol object (``proto.has_reboot``...), never compares protocol numbers."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
# A branch on the protocol number: `protocol == 2`, `bus.protocol != 1`, `protocol_version == 1`.
BRANCH = re.compile(r"protocol(_version)? ?(==|!=) ?[12]\b")
# Only the protocol objects' own definitions may know which protocol they are.
OWN_DEFINITIONS = {
    "poppy_core/protocol/base.py",
    "poppy_core/protocol/v1.py",
    "poppy_core/protocol/v2.py",
}


def test_no_protocol_number_branches_outside_the_protocol_objects() -> None:
    found = [
        f"{path.relative_to(ROOT)}:{number}: {line.strip()}"
        for folder in ("poppy_core", "poppy_cli")
        for path in sorted((ROOT / folder).rglob("*.py"))
        if path.relative_to(ROOT).as_posix() not in OWN_DEFINITIONS
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1)
        if BRANCH.search(line)
    ]
    assert found == [], "ask the protocol object (protocol_for(n)) instead:\n" + "\n".join(found)
