"""Installed profiles load; user profiles override them; names are matched leniently."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from poppy_core.errors import ConfigError
from poppy_core.robot import (
    find_profile,
    list_profiles,
    load_config,
    load_profile,
    profile_dirs,
    user_profile_dir,
)
from poppy_core.robot.profiles import installed_profile_dir

DATA_DIR = Path(__file__).parent / "data"


@pytest.fixture(autouse=True)
def _isolated_user_config(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Point platformdirs at an empty folder so the developer's own profiles do not leak in."""
    home = tmp_path / "xdg"
    monkeypatch.setenv("XDG_CONFIG_HOME", str(home))
    return home


def test_installed_profiles_are_listed() -> None:
    names = [info.name for info in list_profiles()]
    assert names == ["ergo-jr", "humanoid", "torso"]
    for info in list_profiles():
        assert not info.user
        assert info.file == info.directory / "profile.yaml"
        assert info.source.startswith("https://github.com/poppy-project/")
        assert info.kind and info.description


@pytest.mark.parametrize("name", ["ergo-jr", "torso", "humanoid"])
def test_each_profile_loads(name: str) -> None:
    config = load_profile(name)
    assert config.profile is not None and config.profile.name == name
    assert all(c.port == "auto" for c in config.controllers.values())
    assert config.unattached_motors() == []


@pytest.mark.parametrize(
    ("profile", "public"),
    [
        ("ergo-jr", "poppy_ergo_jr"),
        ("torso", "poppy_torso"),
        ("humanoid", "poppy_humanoid"),
    ],
)
def test_profile_matches_public_config(profile: str, public: str) -> None:
    mine = load_profile(profile)
    theirs = load_config(DATA_DIR / f"{public}.json")
    assert mine.motorgroups == theirs.motorgroups
    assert mine.motors.keys() == theirs.motors.keys()
    for name, motor in mine.motors.items():
        other = theirs.motors[name]
        assert (motor.id, motor.type, motor.orientation, motor.offset, motor.angle_limit) == (
            other.id,
            other.type,
            other.orientation,
            other.offset,
            other.angle_limit,
        )
    for name, controller in mine.controllers.items():
        assert mine.motors_of_controller(name) == theirs.motors_of_controller(name)
        assert controller.protocol == theirs.controllers[name].protocol


def test_ergo_jr_is_six_xl320_on_protocol_2() -> None:
    config = load_profile("ergo-jr")
    [controller] = config.controllers.values()
    assert (controller.protocol, controller.baudrate) == (2, 1_000_000)
    assert sorted(m.id for m in config.motors.values()) == [1, 2, 3, 4, 5, 6]
    assert {m.type for m in config.motors.values()} == {"XL-320"}


def test_humanoid_on_two_buses() -> None:
    config = load_profile("humanoid")
    assert set(config.controllers) == {"upper_body_controller", "lower_body_controller"}
    assert len(config.motors) == 25


@pytest.mark.parametrize(
    "spelling", ["ergo_jr", "Ergo-Jr", "poppy-ergo-jr", "poppy_ergo_jr", "ERGOJR"]
)
def test_name_variants(spelling: str) -> None:
    assert find_profile(spelling).name == "ergo-jr"


def test_unknown_profile_lists_known() -> None:
    with pytest.raises(ConfigError) as info:
        load_profile("poppy-dragster")
    assert str(info.value) == (
        'profiles: profile = "poppy-dragster": unknown profile; known: ergo-jr, humanoid, torso'
    )


def test_user_dir_follows_platformdirs(_isolated_user_config: Path) -> None:
    assert user_profile_dir() == _isolated_user_config / "poppy" / "profiles"


def test_user_profile_overrides_installed(_isolated_user_config: Path) -> None:
    installed = installed_profile_dir()
    assert installed is not None
    user_dir = user_profile_dir()
    (user_dir / "torso").mkdir(parents=True)
    text = (installed / "torso" / "profile.yaml").read_text(encoding="utf-8")
    text = text.replace("offset: 20.0", "offset: 25.0")
    (user_dir / "torso" / "profile.yaml").write_text(text, encoding="utf-8")
    assert profile_dirs()[0] == user_dir
    info = find_profile("torso")
    assert info.user and info.directory == user_dir / "torso"
    assert load_profile("torso").motors["head_y"].offset == 25.0
    assert load_profile("humanoid").motors["head_y"].offset == 20.0
    assert len(list_profiles()) == 3


def test_user_profile_added(tmp_path: Path) -> None:
    installed = installed_profile_dir()
    assert installed is not None
    user_dir = tmp_path / "mine"
    (user_dir / "my-arm").mkdir(parents=True)
    shutil.copy(installed / "ergo-jr" / "profile.yaml", user_dir / "my-arm" / "profile.yaml")
    names = [info.name for info in list_profiles(user_dir=user_dir)]
    assert names == ["ergo-jr", "humanoid", "my-arm", "torso"]
    assert load_profile("My_Arm", user_dir=user_dir).motors["m1"].type == "XL-320"


def test_broken_user_profile_is_skipped_in_list_but_fails_on_load(tmp_path: Path) -> None:
    user_dir = tmp_path / "mine"
    (user_dir / "bad").mkdir(parents=True)
    (user_dir / "bad" / "profile.yaml").write_text("controllers: [\n", encoding="utf-8")
    (user_dir / "worse").mkdir()
    (user_dir / "worse" / "profile.yaml").write_text(
        "profile: {name: worse}\ncontrollers: {}\nmotors: {m1: {id: 300}}\n", encoding="utf-8"
    )
    names = [info.name for info in list_profiles(user_dir=user_dir)]
    assert "bad" not in names and "worse" in names
    with pytest.raises(ConfigError, match=r"profile.yaml: motors.m1.id = 300: ID must be"):
        load_profile("worse", user_dir=user_dir)


def test_missing_user_dir_is_ignored(tmp_path: Path) -> None:
    dirs = profile_dirs(user_dir=tmp_path / "absent")
    assert dirs == [installed_profile_dir()]
