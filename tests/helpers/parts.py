"""The parts `make test` splits the suite into: the modules that mostly wait, the rest, OpenGL.

Most of the suite computes on the two cores; a few modules mostly wait (documentation examples
that sleep as written, the README tour's commands, primitives run for their seconds, scans that
wait out absent motors): 920 s of the idle run's 2,216 s of tests' time, at 15 % of a core. In
the same workers as the rest, each of them held a worker the cores could have used. `make test`
runs them in workers of their own beside the others (``POPPY_TEST_PART=waiting``, three
workers, and ``POPPY_TEST_PART=rest``, two per core), so that the cores stay busy while they
wait, and the OpenGL tests in a process that imports only their modules
(``POPPY_TEST_PART=gl``). Unset, a run collects everything, as before.
"""

from __future__ import annotations

import os
from collections.abc import Callable

PART_ENV = "POPPY_TEST_PART"
GL_MARK = "pytest.mark.gl"  # a module marking a test of its own `gl`
PARTS = ("waiting", "rest", "gl")

# Tests that render with OpenGL in the test process. `make test` runs them in a pytest process of
# their own (`POPPY_TEST_PART=gl pytest -m gl`, which imports only these modules and those that
# mark a test `gl` themselves): a render stuck in the driver would otherwise take the whole run
# with it (it happened when mujoco was imported before MUJOCO_GL was set; docs/simulation.md).
GL_MODULES = {
    "gym/test_gym_pixels.py",
    "sim/test_sim_camera.py",
    "sim/test_sim_meshes.py",
    "sim/test_sim_plant.py",
    "sim/test_sim_tracking.py",
}


# The modules over 7 s of one worker that spent under 30 % of it on the CPU (their own and their
# commands'), measured with POPPY_TEST_TIMES on the idle 2-core machine as CI runs the suite
# (2026-12-07, stop 41: wall s, CPU s). A module that drives chromium stays with the browser
# group (tests/conftest.py). Refresh the list from `python -m tests.helpers.timing DIR`.
WAITING_MODULES: dict[str, tuple[float, float]] = {
    "creatures/test_doc_examples.py": (155, 22),
    "cli/test_readme_tour.py": (147, 34),
    "creatures/test_creature_packages.py": (118, 16),
    "cli/test_setup_doctor.py": (43, 1),
    "server/test_snap_pypot_blocks.py": (36, 5),
    "cli/test_scan_emulate.py": (35, 5),
    "cli/test_record_safety.py": (30, 5),
    "tui/test_setup_screen.py": (27, 3),
    "lerobot_plugin/test_zenoh_and_bodies.py": (27, 3),
    "fleet/test_start_time.py": (25, 6),
    "server/test_announce.py": (24, 2),
    "creatures/test_ergo_demos.py": (19, 1),
    "bus/test_slow_adapter.py": (17, 0),
    "robot/test_guided_setup.py": (15, 1),
    "lerobot_plugin/test_contract.py": (14, 1),
    "server/test_snap_cli.py": (13, 3),
    "fleet/test_zenoh_transport_auth.py": (13, 2),
    "kinematics/test_sim_chain.py": (13, 3),
    "cli/test_fleet_discover.py": (12, 1),
    "server/test_limits.py": (11, 2),
    "interop/test_pypot_dxlio.py": (10, 3),
    "motion/test_move_play.py": (10, 1),
    "server/test_snap_session.py": (10, 1),
    "server/test_concurrency_stream.py": (10, 2),
    "ros2/test_ros2_router.py": (10, 2),
    "cli/test_motor_cmd.py": (10, 2),
    "server/test_snap_blocks.py": (9, 1),
    "dataset/test_encoder_process.py": (9, 2),
    "robot/test_factory.py": (9, 1),
    "dataset/test_record_cmd.py": (8, 2),
    "creatures/test_pypot_notebook_names.py": (8, 2),
    "dataset/test_record_keys.py": (8, 1),
    "bus/test_scan.py": (8, 0),
    "robot/test_robot_sim.py": (7, 1),
    "emulator/test_emulator_control.py": (7, 0),
}


class UnknownPart(ValueError):
    """``POPPY_TEST_PART`` names no part."""


def current_part() -> str | None:
    """The part this run collects (``POPPY_TEST_PART``), None for the whole suite."""
    part = os.environ.get(PART_ENV, "").strip()
    if not part:
        return None
    if part not in PARTS:
        raise UnknownPart(
            f"{PART_ENV}={part!r} names no part of the suite: use {' or '.join(PARTS)}, "
            "or unset it for the whole suite"
        )
    return part


def outside_part(module: str, part: str | None, source: Callable[[], str]) -> bool:
    """Whether the test module ``module`` (its path under tests/) is left out of ``part``;
    ``source`` reads its text (the `gl` part keeps a module that marks a test ``gl`` itself)."""
    if part is None:
        return False
    if part == "gl":
        return module not in GL_MODULES and GL_MARK not in source()
    return (module in WAITING_MODULES) != (part == "waiting")
