"""The config's ``kinematics`` section as pydantic models, and the value types the sections share.

``poppy_core.motion.chains`` turns a ``KinematicsSection`` into the kinematics leaf's
``KinematicsSpec`` (the section's form is in ``poppy_core.kinematics.spec``). The ``sensors``
section is ``config_sensors``.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    Strict,
)
from pydantic_core import PydanticCustomError

Name = Annotated[str, Strict()]
Finite = Annotated[float, Strict(), Field(allow_inf_nan=False)]


def _positive(value: float) -> float:
    if not value > 0:
        raise PydanticCustomError("positive", "must be a positive number")
    return value


Positive = Annotated[float, Strict(), Field(allow_inf_nan=False), AfterValidator(_positive)]


def _one_or_many(value: Any) -> Any:
    """None is no name, one name is a list of one (as the hand-written form allows)."""
    if value is None:
        return []
    return [value] if isinstance(value, str) else value


def _identifier(name: str) -> str:
    if not name.isidentifier() or name.startswith("_"):
        raise PydanticCustomError("chain_name", "must be an identifier (not starting with _)")
    return name


Names = Annotated[list[Name], BeforeValidator(_one_or_many)]
ChainName = Annotated[Name, AfterValidator(_identifier)]


def non_empty(value: str) -> str:
    if not value:
        raise PydanticCustomError("empty", "must not be empty")
    return value


def _some(names: list[str]) -> list[str]:
    if not names:
        raise PydanticCustomError("motors", "must list the chain's motors or groups")
    return names


def _xyz(value: Any) -> Any:
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise PydanticCustomError("tip", "must be [x, y, z] in metres")
    return value


def _label(value: str) -> str:
    if value and not value.isidentifier():
        raise PydanticCustomError("label", "must be a name such as arm")
    return value


class ChainSection(BaseModel):
    """One chain: its motors or groups (base to tip), passive and reversed ones, its tip (m),
    and the name people are shown (``label``; the chain's own name stays pypot's attribute)."""

    model_config = ConfigDict(extra="allow")

    motors: Annotated[Names, AfterValidator(_some)]
    passive: Names = Field(default_factory=list)
    reversed: Names = Field(default_factory=list)
    tip: Annotated[tuple[Finite, Finite, Finite], BeforeValidator(_xyz)] = (0.0, 0.0, 0.0)
    label: Annotated[str, AfterValidator(_label)] = ""


class KinematicsSection(BaseModel):
    """The section: the model file (URDF or MJCF), joint frame, chains, reversed motors."""

    model_config = ConfigDict(extra="allow")

    model: Annotated[Name, AfterValidator(non_empty)]
    joint_frame: Literal["motor", "user"] | None = None
    reversed: Names = Field(default_factory=list)
    chains: Annotated[
        dict[ChainName, ChainSection], BeforeValidator(lambda v: {} if v is None else v)
    ] = Field(default_factory=dict)


__all__ = [
    "ChainName",
    "ChainSection",
    "Finite",
    "KinematicsSection",
    "Name",
    "Names",
    "Positive",
    "non_empty",
]
