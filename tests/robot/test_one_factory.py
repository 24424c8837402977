"""One way to build a robot: ``poppy_core.robot``'s factories attach the creature; aliases agree."""

from __future__ import annotations

import pytest

from poppy_core import creatures
from poppy_core.creatures import Dance, attach
from poppy_core.errors import ConfigError
from poppy_core.robot import from_config, from_profile, load_profile, with_ports
from poppy_core.robot.creature_hook import CREATURE_HOOK, resolve_hook


def test_from_profile_attaches_the_creature() -> None:
    with from_profile("ergo-jr", sim=True, sensors=False) as robot:
        assert robot.creature is not None and robot.creature.kind == "ergo-jr"
        assert isinstance(robot.dance, Dance)
        assert robot.emulators["my_dxl_controller"].url.startswith("emu://")


def test_creature_false_builds_a_bare_robot() -> None:
    with from_config(load_profile("ergo-jr"), sim=True, sensors=False, creature=False) as robot:
        assert getattr(robot, "creature", None) is None
        assert not hasattr(robot, "dance")


def test_the_creatures_alias_builds_the_same_robot() -> None:
    with creatures.from_profile("ergo-jr", sim=True, sensors=False, start_defaults=False) as robot:
        assert robot.creature is not None and isinstance(robot.dance, Dance)


def test_the_hook_is_an_entry_point_resolved_at_run_time() -> None:
    assert resolve_hook(CREATURE_HOOK) is attach.attach_behaviours


def test_with_ports_replaces_the_one_port_or_refuses_in_one_line() -> None:
    config = with_ports(load_profile("ergo-jr"), "/dev/ttyACM7", source="command line")
    assert config.controllers["my_dxl_controller"].port == "/dev/ttyACM7"
    with pytest.raises(ConfigError, match="one port given but this robot has 2 controllers"):
        with_ports(load_profile("humanoid"), "/dev/ttyACM7")
