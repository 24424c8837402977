"""The ``kinematics`` section of a config: custom robots get chains; bad sections say why."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from poppy_core import from_config
from poppy_core.errors import ConfigError
from poppy_core.kinematics import load_description
from poppy_core.motion.cartesian import RobotChain
from poppy_core.motion.chains import chains_from_config
from poppy_core.robot import RobotConfig, load_config, load_profile

PROFILES = Path(__file__).resolve().parents[2] / "profiles"


def _custom(tmp_path: Path, kinematics: dict[str, Any], model: str = "poppy_ergo_jr.urdf") -> Path:
    """A robot of its own (the Ergo Jr's motors, kind 'my-arm') with its model next to it."""
    data = load_profile("ergo-jr").to_dict()
    data["profile"] = {"name": "my-arm", "kind": "my-arm"}
    data["kinematics"] = kinematics
    shutil.copy(PROFILES / "ergo-jr" / model, tmp_path / model)
    if model.endswith(".xml"):  # an MJCF model names its meshes (meshdir="meshes")
        shutil.copytree(PROFILES / "ergo-jr" / "meshes", tmp_path / "meshes")
    path = tmp_path / "my-arm.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


ARM = {"motors": ["m1", "m2", "m3", "m4", "m5", "m6"], "tip": [0.0, 0.0, -0.07]}


def test_custom_robot_gets_its_chain(tmp_path: Path) -> None:
    path = _custom(tmp_path, {"model": "poppy_ergo_jr.urdf", "chains": {"arm": ARM}})
    with from_config(path, sim=True) as robot:
        assert not hasattr(robot, "creature")
        chain = robot.arm
        assert isinstance(chain, RobotChain)
        assert chain.position == pytest.approx([0.0, -0.172, 0.1558], abs=1e-3)


def test_custom_robot_with_an_mjcf_model(tmp_path: Path) -> None:
    pytest.importorskip("mujoco")
    path = _custom(tmp_path, {"model": "model.xml", "chains": {"arm": ARM}}, model="model.xml")
    chains = chains_from_config(load_config(path))
    # MJCF joints take the motor angle, as the URDF's: the same pose for the same angles
    urdf_chain = chains_from_config(load_profile("ergo-jr"))["chain"]
    angles = [30.0, -20.0, 10.0, 40.0, -50.0, 60.0]
    assert np.allclose(chains["arm"].forward(angles), urdf_chain.forward(angles), atol=1e-6)


def test_groups_name_the_motors(tmp_path: Path) -> None:
    path = _custom(
        tmp_path,
        {
            "model": "poppy_ergo_jr.urdf",
            "chains": {"arm": {"motors": ["base", "tip"], "passive": ["base"]}},
        },
    )
    chain = chains_from_config(load_config(path))["arm"]
    assert chain.names == ("m1", "m2", "m3", "m4", "m5", "m6")
    assert chain.active_names == ("m4", "m5", "m6")


def test_pypot_json_of_a_creature_gets_the_profile_chains(tmp_path: Path) -> None:
    data = load_profile("torso").to_pypot_dict()
    data.pop("kinematics")
    path = tmp_path / "poppy_torso.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    with from_config(load_config(path), sim=True, start_defaults=False) as robot:
        assert isinstance(robot.l_arm_chain, RobotChain)
        assert isinstance(robot.r_arm_chain, RobotChain)


@pytest.mark.parametrize(
    ("section", "message"),
    [
        ({"model": "nowhere.urdf", "chains": {"arm": ARM}}, "'nowhere.urdf' not found"),
        ({"chains": {"arm": ARM}}, "kinematics.model: missing"),
        (
            {"model": "poppy_ergo_jr.urdf", "chains": {"arm": {"tip": [0, 0, 0]}}},
            "kinematics.chains.arm.motors: missing",
        ),
        (
            {"model": "poppy_ergo_jr.urdf", "chains": {"arm": {**ARM, "tip": [0, 0]}}},
            r"tip = \[0, 0\]: must be \[x, y, z\]",
        ),
        (
            {"model": "poppy_ergo_jr.urdf", "chains": {"arm": {**ARM, "motors": ["m1", "m9"]}}},
            "names 'm9', which is no motor",
        ),
        (
            {"model": "poppy_ergo_jr.urdf", "chains": {"arm": {**ARM, "motors": ["m3", "m1"]}}},
            "from base to tip",
        ),
        (
            {"model": "poppy_ergo_jr.urdf", "chains": {"arm": {**ARM, "motors": ["m1", "m3"]}}},
            "joint 'm2' lies inside the chain",
        ),
        (
            {"model": "poppy_ergo_jr.urdf", "joint_frame": "raw", "chains": {"arm": ARM}},
            "joint_frame = \"raw\": must be 'motor' or 'user'",
        ),
        ({"model": "poppy_ergo_jr.urdf", "chains": {"m1": ARM}}, "already a motor"),
        (
            {"model": "poppy_ergo_jr.urdf", "reversed": ["m7"], "chains": {"arm": ARM}},
            "reversed names 'm7', which is no motor",
        ),
    ],
)
def test_bad_sections_say_what_is_wrong(
    tmp_path: Path, section: dict[str, Any], message: str
) -> None:
    path = _custom(tmp_path, section)
    with pytest.raises(ConfigError, match=message) as caught, from_config(path, sim=True):
        pass
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize(
    ("name", "text"),
    [
        ("bad.xml", "<mujoco><worldbody><body><joint axis='0 0 0'/></body></worldbody></mujoco>"),
        ("bad.xml", "not xml"),
        ("bad.urdf", "<robot><joint name='j'/></robot>"),
        ("bad.urdf", "<robot"),
    ],
)
def test_unreadable_models_are_one_line(tmp_path: Path, name: str, text: str) -> None:
    pytest.importorskip("mujoco")
    (tmp_path / name).write_text(text, encoding="utf-8")
    with pytest.raises(ConfigError) as caught:
        load_description(tmp_path / name)
    assert name in str(caught.value) and "\n" not in str(caught.value)


def test_section_must_be_a_mapping() -> None:
    data = {"controllers": {}, "motors": {}, "kinematics": ["model.urdf"]}
    with pytest.raises(ConfigError, match=r"kinematics = .*: must be a valid dictionary"):
        RobotConfig.from_dict(data)
