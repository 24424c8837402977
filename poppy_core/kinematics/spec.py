"""The ``kinematics`` section of a robot config (model file, chains) and the chains built from it.

```yaml
kinematics:
  model: poppy_torso.urdf          # URDF or MJCF; relative to the config file's folder
  joint_frame: motor               # optional: motor (the default, pypot's) or user
  reversed: [r_shoulder_x]         # motors turning against the model's axis, in every chain
  chains:
    l_arm_chain:
      motors: [torso, l_arm]       # motors or groups, base to tip
      passive: [torso]             # joints the solver leaves where they are
      reversed: []                 # ... in this chain only (pypot's reversed_motors)
      tip: [0, 0.18, 0]            # metres, in the last joint's child frame
```

The section is checked with the rest of the config (``poppy_core.robot.config_sections``, every
problem at once); this leaf receives the plain ``KinematicsSpec``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from poppy_core.errors import ConfigError
from poppy_core.kinematics.chain import Chain, ChainJoint
from poppy_core.kinematics.description import JointFrame, KinematicDescription

SECTION = "kinematics"


@dataclass(frozen=True)
class ChainSpec:
    """One chain of the config: its motors (base to tip), passive and reversed ones, its tip,
    and the name people are shown (``label``: the Ergo Jr's ``chain``, pypot's attribute name,
    is shown as ``arm``; the name itself is kept for ``robot.chain`` and the APIs)."""

    name: str
    motors: tuple[str, ...]
    passive: tuple[str, ...] = ()
    reversed: tuple[str, ...] = ()
    tip: tuple[float, float, float] = (0.0, 0.0, 0.0)
    label: str = ""

    @property
    def shown(self) -> str:
        """The chain's name for people: its label, else its name."""
        return self.label or self.name


@dataclass(frozen=True)
class KinematicsSpec:
    """The whole section: model file (as written), joint frame, chains, reversed motors.

    ``reversed`` lists the motors that turn against the model's axis in every chain (a model
    whose axis disagrees with the servo's), on top of each chain's own ``reversed``.
    """

    model: str
    chains: tuple[ChainSpec, ...]
    joint_frame: JointFrame | None = None
    reversed: tuple[str, ...] = ()


@dataclass(frozen=True)
class MotorFrame:
    """What a chain needs to know of a motor: orientation sign, offset and angle limits."""

    sign: float
    offset_deg: float
    limits_deg: tuple[float, float]


def find_model(model: str, folders: Iterable[Path]) -> Path:
    """The model file: an absolute path, or the first folder holding it.

    Raises:
        ConfigError: the file is in none of the folders.
    """
    path = Path(model).expanduser()
    if path.is_absolute():
        if path.is_file():
            return path
        raise ConfigError(f"kinematic model {path} not found", field=f"{SECTION}.model")
    tried = []
    for folder in folders:
        candidate = folder / path
        if candidate.is_file():
            return candidate
        tried.append(str(folder))
    raise ConfigError(
        f"kinematic model {model!r} not found (looked in {', '.join(tried) or 'no folder'}): "
        "give a path relative to the config file or an absolute one",
        field=f"{SECTION}.model",
        value=model,
    )


def build_chains(
    spec: KinematicsSpec,
    description: KinematicDescription,
    motors: Mapping[str, MotorFrame],
    expand: Callable[[str], Sequence[str]] | None = None,
) -> dict[str, Chain]:
    """The chains of ``spec`` on ``description``, with the motors' frames and limits.

    Args:
        spec: the config's section.
        description: the model it names (``load_description``).
        motors: motor name -> its orientation sign, offset and limits.
        expand: group name -> motor names (names that are not groups come back alone).

    Raises:
        ConfigError: an unknown motor or a chain that is not one branch of the model.
    """
    frame = spec.joint_frame or description.joint_frame

    def flat(names: Iterable[str]) -> list[str]:
        out: list[str] = []
        for name in names:
            out.extend(n for n in (expand(name) if expand else [name]) if n not in out)
        return out

    for name in flat(spec.reversed):
        if name not in motors:
            raise ConfigError(
                f"{SECTION}.reversed names {name!r}, which is no motor of the robot",
                field=f"{SECTION}.reversed",
                value=name,
            )
    chains: dict[str, Chain] = {}
    for chain in spec.chains:
        names = flat(chain.motors)
        passive = set(flat(chain.passive))
        reversed_ = set(flat(chain.reversed)) | set(flat(spec.reversed))
        joints = []
        for name in names:
            motor = motors.get(name)
            if motor is None:
                raise ConfigError(
                    f"chain {chain.name!r} names {name!r}, which is no motor of the robot",
                    field=f"{SECTION}.chains.{chain.name}.motors",
                    value=name,
                )
            scale = motor.sign if frame == "motor" else 1.0
            joints.append(
                ChainJoint(
                    name=name,
                    limits_deg=motor.limits_deg,
                    scale=-scale if name in reversed_ else scale,
                    offset_deg=motor.offset_deg if frame == "motor" else 0.0,
                    active=name not in passive,
                )
            )
        chains[chain.name] = Chain(chain.name, description, joints, chain.tip, label=chain.shown)
    return chains
