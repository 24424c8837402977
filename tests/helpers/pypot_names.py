"""Names pypot's creatures give their primitives, restated once for the tests that check them.

Source: the ``attach_primitive`` calls of poppy-torso 3.0.0 (``poppy_torso.py``) and the Poppy
documentation (the Torso's list at line 1969, the Humanoid's postures). The order is poppy's
``primitive_names`` (init_position last).
"""

from __future__ import annotations

UPPER_BODY_PRIMITIVES = [
    "limit_torque",
    "temperature_monitoring",
    "dance_beat_motion",
    "upper_body_idle_motion",
    "head_idle_motion",
    "arms_turn_compliant",
    "arms_copy_motion",
]
"""What the Torso and the Humanoid share."""
TORSO_PRIMITIVES = [*UPPER_BODY_PRIMITIVES, "init_position"]
HUMANOID_PRIMITIVES = ["stand_position", "sit_position", *UPPER_BODY_PRIMITIVES]
