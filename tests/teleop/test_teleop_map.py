"""``JointMap``: the FOLLOWER=[-][SCALE*]LEADER[+OFFSET] syntax, YAML files, checks."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from poppy_core.errors import ConfigError
from poppy_core.motion.teleop.joint_map import JointLink, JointMap

names = st.from_regex(r"[a-z_][a-z0-9_]{0,8}", fullmatch=True)
numbers = st.decimals(min_value=0, max_value=1000, places=2).map(float)


def test_parse_reads_signs_scales_and_offsets() -> None:
    parsed = JointMap.parse("r_shoulder_y=m2, r_shoulder_x = -m1, r_elbow_y=0.5*m3+10, w=-2*m4-7.5")
    assert parsed.links == (
        JointLink("r_shoulder_y", "m2"),
        JointLink("r_shoulder_x", "m1", -1.0),
        JointLink("r_elbow_y", "m3", 0.5, 10.0),
        JointLink("w", "m4", -2.0, -7.5),
    )
    assert parsed.apply({"m1": 10, "m2": 20, "m3": 30, "m4": 1}) == {
        "r_shoulder_y": 20,
        "r_shoulder_x": -10,
        "r_elbow_y": 25,
        "w": -9.5,
    }
    assert parsed.leaders == ["m2", "m1", "m3", "m4"]


@given(names, names, st.sampled_from([1.0, -1.0]) | numbers, st.sampled_from([0.0]) | numbers)
def test_the_text_form_parses_back(follower: str, leader: str, scale: float, offset: float) -> None:
    if scale == 0:
        scale = 1.0
    link = JointLink(follower, leader, scale, offset)
    assert JointMap.parse(str(JointMap((link,)))).links == (link,)


@pytest.mark.parametrize(
    "text", ["m1", "m1=", "=m2", "m1=m2*3", "m1=m2+", "m1=2*-m2", "m 1=m2", "m1=m2,m1=m3", ""]
)
def test_bad_text_is_refused_in_one_line(text: str) -> None:
    with pytest.raises(ConfigError) as caught:
        JointMap.parse(text)
    assert "\n" not in str(caught.value)


def test_same_names_and_check_against_the_robots() -> None:
    mapping = JointMap.same_names(["m1", "m2", "m3"], ["m2", "m3", "m9"])
    assert mapping.followers == ["m2", "m3"]
    with pytest.raises(ConfigError, match="no motor name in common"):
        JointMap.same_names(["m1"], ["l_elbow_y"])
    with pytest.raises(ConfigError, match="the leader has no motor m7"):
        JointMap.parse("m1=m7").check(["m1", "m2"], ["m1"])
    with pytest.raises(ConfigError, match="the follower has no motor x"):
        JointMap.parse("x=m1").check(["m1"], ["m1"])


def test_yaml_file(tmp_path: Path) -> None:
    file = tmp_path / "map.yaml"
    file.write_text("r_elbow_y: m3\nr_arm_z: {leader: m4, scale: -1, offset: 5}\n")
    assert JointMap.load(file).links == (
        JointLink("r_elbow_y", "m3"),
        JointLink("r_arm_z", "m4", -1.0, 5.0),
    )
    for text, message in [
        ("[m1, m2]", "a mapping follower: leader"),
        ("a: {leader: m1, gain: 2}", "unknown key 'gain'"),
        ("a: {leader: m1, scale: two}", "scale must be a number"),
        ("a: {scale: 2}", "give a leader joint name"),
        ("a: [", "YAML syntax error"),
    ]:
        file.write_text(text)
        with pytest.raises(ConfigError, match=message):
            JointMap.load(file)
    with pytest.raises(ConfigError, match="cannot read"):
        JointMap.load(tmp_path / "missing.yaml")


def test_a_map_file_is_read_through_the_bounded_loaders(tmp_path: Path) -> None:
    file = tmp_path / "map.yaml"
    file.write_text("m1: m2\n" + "# padding\n" * 40_000)  # 400 kB
    with pytest.raises(ConfigError, match="bytes"):
        JointMap.load(file)
    file.write_text("a: " + "[" * 5000 + "]" * 5000)
    with pytest.raises(ConfigError, match="nested more than"):
        JointMap.load(file)
    laughs = ["l0: &l0 [x, x, x, x, x, x, x, x, x]"]
    laughs += [f"l{i}: &l{i} [{', '.join([f'*l{i - 1}'] * 9)}]" for i in range(1, 6)]
    file.write_text("\n".join(laughs))
    with pytest.raises(ConfigError, match="aliases"):
        JointMap.load(file)
    with pytest.raises(ConfigError, match="a folder"):
        JointMap.load(tmp_path)


def test_the_shipped_example_map_loads() -> None:
    example = Path(__file__).parents[2] / "docs" / "examples" / "ergo-jr-to-torso-arm.yaml"
    mapping = JointMap.load(example)
    mapping.check(
        [f"m{i}" for i in range(1, 7)], ["r_shoulder_y", "r_shoulder_x", "r_arm_z", "r_elbow_y"]
    )
