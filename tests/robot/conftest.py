"""Shared fixtures for the robot config and profile tests."""

from __future__ import annotations

import copy
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

# Copies of the public pypot configs of the Poppy project (poppy-ergo-jr, poppy-torso,
# poppy-humanoid repositories, software/<robot>/configuration/<robot>.json).
DATA_DIR = Path(__file__).parent / "data"
PUBLIC_CONFIGS = ("poppy_ergo_jr", "poppy_torso", "poppy_humanoid")


def public_config_path(name: str) -> Path:
    """The copy of one public Poppy config."""
    return DATA_DIR / f"{name}.json"


def small_config() -> dict[str, Any]:
    """A valid two-bus config used as the base of the error cases."""
    return {
        "controllers": {
            "upper": {"port": "auto", "sync_read": False, "attached_motors": ["arm"]},
            "lower": {"port": "/dev/ttyUSB1", "sync_read": True, "attached_motors": ["m3"]},
        },
        "motorgroups": {"arm": ["m1", "m2"], "all": ["arm", "m3"]},
        "motors": {
            "m1": {
                "id": 1,
                "type": "MX-28",
                "orientation": "direct",
                "offset": 0.0,
                "angle_limit": [-90.0, 90.0],
            },
            "m2": {
                "id": 2,
                "type": "AX-12",
                "orientation": "indirect",
                "offset": 10,
                "angle_limit": [-150, 150],
            },
            "m3": {
                "id": 1,
                "type": "MX-64",
                "orientation": "direct",
                "offset": 0.0,
                "angle_limit": [-45.0, 45.0],
            },
        },
    }


@pytest.fixture
def base_config() -> Callable[[], dict[str, Any]]:
    """A factory of fresh copies of ``small_config()``."""
    return lambda: copy.deepcopy(small_config())


@pytest.fixture(params=PUBLIC_CONFIGS)
def public_config(request: pytest.FixtureRequest) -> tuple[Path, dict[str, Any]]:
    """Each public Poppy config: its path and its parsed JSON."""
    path = public_config_path(str(request.param))
    return path, json.loads(path.read_text(encoding="utf-8"))
