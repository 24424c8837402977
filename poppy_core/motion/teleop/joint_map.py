"""``JointMap``: which leader joint drives which follower joint, with a scale and an offset.

Angles are in each robot's user frame, so two calibrated robots of one kind map one to one (their
calibrations already agree on what 0° means). Different creatures need a map, written
``FOLLOWER=LEADER`` entries such as ``r_shoulder_y=m2, r_shoulder_x=-m1, r_elbow_y=0.8*m3+10``
or a YAML file ``{follower: leader}`` / ``{follower: {leader: m3, scale: 0.8, offset: 10}}``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from poppy_core.documents import Limits, parse_yaml, read_limited
from poppy_core.errors import ConfigError

_NAME = r"[A-Za-z_][A-Za-z0-9_]*"
_NUMBER = r"[0-9]+(?:\.[0-9]*)?|\.[0-9]+"
_ENTRY = re.compile(
    rf"^\s*(?P<follower>{_NAME})\s*=\s*(?P<sign>-)?\s*(?:(?P<scale>{_NUMBER})\s*\*\s*)?"
    rf"(?P<leader>{_NAME})\s*(?:(?P<op>[+-])\s*(?P<offset>{_NUMBER}))?\s*$"
)
MAP_LIMITS = Limits(max_bytes=256 << 10, max_nodes=20_000, max_depth=8)
"""A joint map file: the Humanoid's is a few hundred values, two levels deep."""
SYNTAX = "FOLLOWER=[-][SCALE*]LEADER[+OFFSET], e.g. r_elbow_y=-m3 or r_arm_z=0.5*m4+10"


@dataclass(frozen=True)
class JointLink:
    """``follower = scale * leader + offset`` (degrees, user frames)."""

    follower: str
    leader: str
    scale: float = 1.0
    offset: float = 0.0

    def apply(self, leader_deg: float) -> float:
        """The follower's target for a leader angle."""
        return self.scale * leader_deg + self.offset

    def __str__(self) -> str:
        scale = "" if self.scale == 1 else ("-" if self.scale == -1 else f"{self.scale:g}*")
        offset = "" if self.offset == 0 else f"{self.offset:+g}"
        return f"{self.follower}={scale}{self.leader}{offset}"


@dataclass(frozen=True)
class JointMap:
    """The links of a teleoperation, one per follower joint."""

    links: tuple[JointLink, ...]

    def __post_init__(self) -> None:
        if not self.links:
            raise ConfigError("the joint map links no joint", field="map")
        seen: set[str] = set()
        for link in self.links:
            if link.follower in seen:
                raise ConfigError(
                    f"follower joint {link.follower!r} is mapped twice",
                    field="map",
                    value=link.follower,
                )
            seen.add(link.follower)
            if not (math.isfinite(link.scale) and math.isfinite(link.offset)):
                raise ConfigError(f"{link}: scale and offset must be finite", field="map")

    @property
    def leaders(self) -> list[str]:
        """Leader joints read, each once, in map order."""
        return list(dict.fromkeys(link.leader for link in self.links))

    @property
    def followers(self) -> list[str]:
        """Follower joints driven, in map order."""
        return [link.follower for link in self.links]

    def apply(self, leader_positions: Mapping[str, float]) -> dict[str, float]:
        """Follower targets from leader positions (degrees, user frames)."""
        return {link.follower: link.apply(leader_positions[link.leader]) for link in self.links}

    def check(self, leader_motors: Iterable[str], follower_motors: Iterable[str]) -> None:
        """Refuse links naming motors the robots do not have.

        Raises:
            ConfigError: one line naming the unknown joints and the known ones.
        """
        for side, names, known in (
            ("leader", self.leaders, list(leader_motors)),
            ("follower", self.followers, list(follower_motors)),
        ):
            missing = [n for n in names if n not in known]
            if missing:
                raise ConfigError(
                    f"the {side} has no motor {', '.join(missing)} (its motors: "
                    f"{', '.join(known)})",
                    field="map",
                    value=missing,
                )

    def __str__(self) -> str:
        return ", ".join(str(link) for link in self.links)

    # -- building ----------------------------------------------------------------------------

    @classmethod
    def same_names(cls, leader_motors: Sequence[str], follower_motors: Sequence[str]) -> JointMap:
        """Each follower joint driven by the leader joint of the same name.

        Raises:
            ConfigError: the robots share no motor name (a map is needed).
        """
        shared = [name for name in follower_motors if name in set(leader_motors)]
        if not shared:
            raise ConfigError(
                "the leader and the follower have no motor name in common: give a joint map "
                f"({SYNTAX})",
                field="map",
            )
        return cls(tuple(JointLink(name, name) for name in shared))

    @classmethod
    def parse(cls, text: str) -> JointMap:
        """A map from comma-separated ``FOLLOWER=[-][SCALE*]LEADER[+OFFSET]`` entries.

        Raises:
            ConfigError: an entry that does not follow the syntax (the message shows it).
        """
        links = []
        for part in text.split(","):
            if not part.strip():
                continue
            match = _ENTRY.match(part)
            if match is None:
                raise ConfigError(
                    f"{part.strip()!r} is not a joint link: write {SYNTAX}",
                    field="map",
                    value=part.strip(),
                )
            scale = float(match["scale"]) if match["scale"] else 1.0
            if match["sign"]:
                scale = -scale
            offset = float(match["offset"]) if match["offset"] else 0.0
            if match["op"] == "-":
                offset = -offset
            links.append(JointLink(match["follower"], match["leader"], scale, offset))
        return cls(tuple(links))

    @classmethod
    def from_data(cls, data: Any, source: str = "map") -> JointMap:
        """A map from ``{follower: leader}`` or ``{follower: {leader, scale, offset}}`` data.

        Raises:
            ConfigError: anything else, naming the entry.
        """
        if not isinstance(data, Mapping) or not data:
            raise ConfigError(
                f"{source}: a joint map is a mapping follower: leader", file=source, field="map"
            )
        links = []
        for follower, entry in data.items():
            where = f"{source}: {follower}"
            if isinstance(entry, str):
                links.append(JointLink(str(follower), entry))
                continue
            if not isinstance(entry, Mapping) or not isinstance(entry.get("leader"), str):
                raise ConfigError(
                    f"{where}: give a leader joint name or {{leader: NAME, scale: 1, offset: 0}}",
                    file=source,
                    field=str(follower),
                )
            extra = set(entry) - {"leader", "scale", "offset"}
            if extra:
                raise ConfigError(
                    f"{where}: unknown key {sorted(extra)[0]!r} (keys: leader, scale, offset)",
                    file=source,
                    field=str(follower),
                )
            numbers = []
            for key, default in (("scale", 1.0), ("offset", 0.0)):
                value = entry.get(key, default)
                if isinstance(value, bool) or not isinstance(value, int | float):
                    raise ConfigError(
                        f"{where}: {key} must be a number", file=source, field=f"{follower}.{key}"
                    )
                numbers.append(float(value))
            links.append(JointLink(str(follower), entry["leader"], numbers[0], numbers[1]))
        return cls(tuple(links))

    @classmethod
    def load(cls, path: str | Path) -> JointMap:
        """A map from a YAML (or JSON) file (see ``from_data``).

        Raises:
            ConfigError: the file cannot be read or is not a joint map.
        """
        file = Path(path)
        data = parse_yaml(
            read_limited(file, MAP_LIMITS.max_bytes, "joint map"), str(file), MAP_LIMITS
        )
        return cls.from_data(data, str(file))
