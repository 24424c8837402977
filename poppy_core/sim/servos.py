"""Servo parameters of the MuJoCo plant: gain, force range, damping, armature, friction per model.

Sources and reasoning (see docs/simulation.md):

- stall torque and no-load speed: the e-manual "Specifications" of each model, already held by
  ``poppy_core.models`` (XL-320 0.39 N·m / 114 rpm at 7.4 V; AX-12A 1.5 N·m / 59 rpm at 12 V;
  MX-28 2.5 N·m / 55 rpm at 12 V; MX-64 6.0 N·m / 63 rpm at 12 V);
- force range = stall torque (times the torque limit register, in %);
- back-EMF damping while driven = stall torque / no-load speed: the slope of a DC motor's
  torque-speed line, the linear model used in published Dynamixel identifications;
- proportional gain: full stall torque at ``saturation_deg`` of error. AX-12A: the default
  compliance slope (32 steps, 9.4°, e-manual AX-12A "Compliance Slope"); the others: an
  estimate of 5°, the stiffness seen on real Poppy arms (a few degrees of sag under load);
- armature (reflected rotor inertia, J_rotor × gear ratio²) and dry friction of the gear train:
  estimates of the order identified for MX-64/MX-106 by Rhoban's servo identification
  (Duclusaud, Passault et al., "Extended friction models for the physics simulation of servo
  actuators", 2024), scaled by gear ratio and size for the smaller models.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from poppy_core.models import ServoModel


@dataclass(frozen=True)
class ServoParams:
    """Physical parameters of one servo model in the simulation (SI units, joint side)."""

    model: str
    stall_torque_nm: float
    no_load_speed_dps: float
    saturation_deg: float
    armature_kgm2: float
    friction_nm: float

    @property
    def kp_nm_per_rad(self) -> float:
        """Position gain: stall torque reached at ``saturation_deg`` of error."""
        return self.stall_torque_nm / math.radians(self.saturation_deg)

    @property
    def kv_nms_per_rad(self) -> float:
        """Back-EMF damping while the motor is driven: stall torque / no-load speed."""
        return self.stall_torque_nm / math.radians(self.no_load_speed_dps)


# model name -> (saturation_deg, armature_kgm2, friction_nm); estimates, see the module doc.
_ESTIMATES: dict[str, tuple[float, float, float]] = {
    "XL-320": (5.0, 0.0012, 0.01),
    "AX-12A": (9.4, 0.006, 0.03),
    "AX-12W": (9.4, 0.002, 0.02),
    "AX-18A": (9.4, 0.006, 0.03),
    "MX-28": (5.0, 0.009, 0.05),
    "MX-64": (5.0, 0.012, 0.10),
    "MX-106": (5.0, 0.018, 0.15),
}
_DEFAULT = (5.0, 0.008, 0.05)


def servo_params(model: ServoModel) -> ServoParams:
    """The simulation parameters of ``model`` (datasheet values plus the estimates above)."""
    saturation, armature, friction = _ESTIMATES.get(model.name, _DEFAULT)
    return ServoParams(
        model=model.name,
        stall_torque_nm=model.stall_torque_nm,
        no_load_speed_dps=model.no_load_speed_dps,
        saturation_deg=saturation,
        armature_kgm2=armature,
        friction_nm=friction,
    )
