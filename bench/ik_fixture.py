"""Record pypot's chain positions for a set of poses: ``tests/kinematics/data/pypot_chains.json``.

``.venv/bin/python -m bench.ik_fixture`` (needs the peers venv). The tests compare poppy's chains
with these answers, so CI needs no pypot.
"""

from __future__ import annotations

import json
import sys
from typing import Any

import numpy as np

from bench.clients import PEERS_PYTHON
from bench.ik_peers import run_pypot_ik
from bench.registry import REPO_ROOT

FIXTURE = REPO_ROOT / "tests" / "kinematics" / "data" / "pypot_chains.json"
POSES_PER_CHAIN = 25
KINDS = ["ergo-jr", "torso", "humanoid"]


def poses(seed: int = 13) -> dict[str, dict[str, Any]]:
    """Per creature and chain: its motors and poses (0° first, then random within limits)."""
    from poppy_core.motion.chains import chains_from_config
    from poppy_core.robot import load_profile

    rng = np.random.default_rng(seed)
    out: dict[str, dict[str, Any]] = {}
    for kind in KINDS:
        config = load_profile(kind)
        for name, chain in chains_from_config(config).items():
            limits = np.array([j.limits_deg for j in chain.joints])
            listed = [[0.0] * len(chain.joints)]
            listed += [
                [round(float(v), 3) for v in rng.uniform(limits[:, 0], limits[:, 1])]
                for _ in range(POSES_PER_CHAIN - 1)
            ]
            out.setdefault(kind, {})[name] = {"motors": list(chain.names), "poses": listed}
    return out


def main() -> int:
    """Ask pypot for every pose's tip pose and write the fixture."""
    if not PEERS_PYTHON.exists():
        sys.stderr.write("the peers venv is missing: bash bench/setup_peers.sh\n")
        return 1
    record: dict[str, Any] = {
        "source": (
            "pypot 5.0.2 IKChain.from_poppy_creature (ikpy 3.0.1) on the public Poppy URDFs in "
            "profiles/, chains defined as in poppy_ergo_jr.py and poppy_torso.py (the Humanoid "
            "with the Torso's definitions); recorded by bench/ik_fixture.py through "
            "bench/peers/pypot_ik.py. Angles in degrees (user frame), poses 4x4 in metres."
        ),
        "creatures": {},
    }
    for kind, chains in poses().items():
        job = {"job": "forward", "poses": {n: c["poses"] for n, c in chains.items()}}
        answer = run_pypot_ik(PEERS_PYTHON, [kind], job)["poses"]
        record["creatures"][kind] = {
            name: {**chain, "tip_poses": [np.round(np.array(p), 9).tolist() for p in answer[name]]}
            for name, chain in chains.items()
        }
    FIXTURE.write_text(json.dumps(record, indent=1) + "\n", encoding="utf-8")
    sys.stdout.write(f"wrote {FIXTURE}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
