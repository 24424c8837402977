"""Motion: trajectories (minimum jerk, constant speed); primitives and moves build on them."""

from poppy_core.motion.trajectory import CONTROLS, MinimumJerk, dummy_speed

__all__ = ["CONTROLS", "MinimumJerk", "dummy_speed"]
