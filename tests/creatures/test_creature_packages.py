"""Every primitive of poppy-ergo-jr, poppy-torso and poppy-humanoid, run on poppy as on pypot.

The packages' ``primitives/`` modules come from PyPI (``tests/helpers/creature_packages.py``),
with only their pypot imports changed; each of the 29 primitives their ``setup()`` attaches is
built, attached, started, run a second (or to its end) and stopped, on the dummy creature and on
MuJoCo (``creature_primitives.replay``). The same replay on pypot 5.0.2's dummy robots is the
oracle: what runs clean there runs clean here, and what fails there (a bug of the package)
fails here with the same exception.
"""

from __future__ import annotations

import logging
from pathlib import Path

import pytest

from poppy_core.creatures.postures import clamp_to_limits
from poppy_core.motion import SimplePosture
from poppy_core.pypot import PoppyErgoJr, PoppyHumanoid, PoppyTorso
from tests.creatures.creature_primitives import ATTACHED, EXPECTED_FAILURES, PACKAGES, replay
from tests.helpers.creature_packages import creature_primitives

pytestmark = pytest.mark.slow

CREATURES = {
    "poppy-ergo-jr": PoppyErgoJr,
    "poppy-torso": PoppyTorso,
    "poppy-humanoid": PoppyHumanoid,
}


@pytest.mark.parametrize("sim", ["dummy", "mujoco"])
@pytest.mark.parametrize("creature", list(CREATURES))
def test_every_primitive_of_the_package_runs_as_on_pypot(
    creature: str, sim: str, tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    package, version = PACKAGES[creature]
    modules = creature_primitives(creature, version, package, tmp_path)
    sound = str(tmp_path / "error.wav")  # only played above 55 °C
    mismatches: list[str] = []
    with CREATURES[creature](simulator=sim) as robot:
        for entry in [e for e in ATTACHED if e.creature == creature]:
            caplog.clear()
            with caplog.at_level(logging.WARNING, logger="poppy_core.motion"):
                primitive, seen = replay(
                    robot, entry, vars(modules[entry.module]), sound, lambda p: p.is_alive()
                )
            died = [
                r.getMessage().splitlines()[0] for r in caplog.records if "died" in r.getMessage()
            ]
            expected = EXPECTED_FAILURES.get((creature, entry.name))
            if expected is None and (seen or died):
                mismatches.append(f"{entry.name} ({entry.cls}): {seen or died}")
            elif expected is not None and not (seen and seen[0].startswith(expected)):
                mismatches.append(
                    f"{entry.name} ({entry.cls}): pypot fails with {expected}, poppy {seen}"
                )
            if isinstance(primitive, SimplePosture) and not seen:
                # a posture ends where it says: its read-only target_position, inside the limits
                target = clamp_to_limits(robot, primitive.target_position)
                reached = {n: round(robot.motor(n).goal_position, 1) for n in target}
                if any(abs(reached[n] - v) > 0.5 for n, v in target.items()):
                    mismatches.append(f"{entry.name}: goals {reached}, not {target}")
    assert not mismatches, "\n".join(mismatches)
