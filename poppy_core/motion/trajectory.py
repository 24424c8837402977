"""The trajectory maths, kept importable here: it lives in the leaf ``poppy_core.trajectory``."""

from poppy_core.trajectory import (
    CONTROL_SPELLINGS,
    CONTROLS,
    MAX_DURATION_S,
    GotoPlan,
    MinimumJerk,
    check_goto,
    control_name,
    dummy_speed,
    plan_goto,
)

__all__ = [
    "CONTROLS",
    "CONTROL_SPELLINGS",
    "MAX_DURATION_S",
    "GotoPlan",
    "MinimumJerk",
    "check_goto",
    "control_name",
    "dummy_speed",
    "plan_goto",
]
