"""A person's arm directions, and the arm joints of a Torso or Humanoid that point the same way.

The person's frame comes from the skeleton itself (any right-handed frame: the Kinect's, a
camera pose's): left from the right shoulder to the left one, up from the hips' centre to the
shoulders' (made square to left), forward = left x up. The upper arm goes from the shoulder to
the elbow, the forearm from the elbow to the wrist; each is given as (forward, left, up).

The robot's frame comes from its own kinematics: with the torso where it is and the arm joints
at 0 (the upper arm hanging down, the forearm pointing forward, the profiles' calibration
posture), up is against the upper arm and forward along the forearm. The arm joints that point
the robot's upper arm and forearm along wanted directions are found by damped least squares on
the chain's forward kinematics (shoulder: the second arm joint's origin; elbow: the last arm
joint's; hand: the chain's tip), within the joints' limits.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from poppy_core.kinematics.chain import Chain

Directions = tuple[np.ndarray, np.ndarray]
"""An arm's upper-arm and forearm unit vectors."""
FOREARM_WEIGHT = 0.7
"""The forearm counts a little less than the upper arm (its direction is noisier)."""
STEP_DEG = 0.5
MAX_STEP_DEG = 30.0
ITERATIONS = 40


def unit(vector: Any) -> np.ndarray:
    """``vector`` scaled to length 1 (zero stays zero)."""
    v = np.asarray(vector, dtype=float)
    norm = float(np.linalg.norm(v))
    return v / norm if norm > 1e-9 else v * 0.0


def body_frame(left: Any, up: Any) -> np.ndarray:
    """Rows forward, left, up (unit, square) from a left and a rough up direction."""
    lft = unit(left)
    upw = unit(np.asarray(up, dtype=float) - lft * float(np.dot(up, lft)))
    return np.array([np.cross(lft, upw), lft, upw])


def person_arms(skeleton: Any) -> dict[str, Directions]:
    """Each of the person's arms (``left``, ``right``) in the person's frame (forward, left, up).

    Args:
        skeleton: a ``Skeleton`` (Kinect or camera pose): joints with a ``position``.
    """

    def at(name: str) -> np.ndarray:
        return np.asarray(getattr(skeleton, name).position, dtype=float)

    frame = body_frame(
        at("shoulder_left") - at("shoulder_right"), at("shoulder_center") - at("hip_center")
    )
    arms = {}
    for side in ("left", "right"):
        upper = unit(at(f"elbow_{side}") - at(f"shoulder_{side}"))
        fore = unit(at(f"wrist_{side}") - at(f"elbow_{side}"))
        arms[side] = (frame @ upper, frame @ fore)
    return arms


def robot_arm_for(arms: Mapping[str, Directions], robot_side: str, mirror: bool) -> Directions:
    """What the robot's ``robot_side`` arm copies: the same arm, or mirrored (the person's other
    arm, its left-right part turned over, as a mirror image does)."""
    if not mirror:
        return arms[robot_side]
    other = "right" if robot_side == "left" else "left"
    flip = np.array([1.0, -1.0, 1.0])
    upper, fore = arms[other]
    return upper * flip, fore * flip


class ArmSolver:
    """The arm joints of one chain (Torso, Humanoid) for wanted arm directions.

    Args:
        model: the chain's kinematic model (``robot.l_arm_chain.model``).
        arm: the arm's joints, shoulder first, elbow last (``l_shoulder_y`` ... ``l_elbow_y``).
        limits: each arm joint's (min, max) in degrees.
    """

    def __init__(
        self, model: Chain, arm: Sequence[str], limits: Mapping[str, tuple[float, float]]
    ) -> None:
        self.model = model
        self.arm = tuple(arm)
        self.low = np.array([limits[n][0] for n in self.arm])
        self.high = np.array([limits[n][1] for n in self.arm])

    def points(self, angles: Mapping[str, float]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Shoulder, elbow and hand in the chain's base frame for ``angles`` (degrees)."""
        frames = self.model.frames(dict(angles))
        return (
            frames[self.arm[1]][:3, 3],
            frames[self.arm[-1]][:3, 3],
            frames["tip"][:3, 3],
        )

    def directions(self, angles: Mapping[str, float]) -> Directions:
        """The upper arm's and the forearm's unit vectors in the chain's base frame."""
        shoulder, elbow, hand = self.points(angles)
        return unit(elbow - shoulder), unit(hand - elbow)

    def frame(self, torso: Mapping[str, float]) -> np.ndarray:
        """The robot's rows forward, left, up in the chain's base frame (its torso at ``torso``)."""
        upper, fore = self.directions({**torso, **dict.fromkeys(self.arm, 0.0)})
        up = -upper
        forward = unit(fore - up * float(fore @ up))
        return np.array([forward, np.cross(up, forward), up])

    def _residual(self, q: np.ndarray, fixed: Mapping[str, float], want: Directions) -> np.ndarray:
        upper, fore = self.directions({**fixed, **dict(zip(self.arm, q, strict=True))})
        return np.concatenate([upper - want[0], FOREARM_WEIGHT * (fore - want[1])])

    def solve(
        self, want: Directions, fixed: Mapping[str, float], seeds: Sequence[Mapping[str, float]]
    ) -> tuple[dict[str, float], float]:
        """The arm joints pointing as ``want`` (base frame), within limits, and the error left
        (the residual's norm), from the best of ``seeds``; ``fixed`` holds the torso's angles."""
        best: tuple[np.ndarray, float] | None = None
        for seed in seeds:
            q = np.clip([float(seed.get(n, 0.0)) for n in self.arm], self.low, self.high)
            q, cost = self._descend(q, fixed, want)
            if best is None or cost < best[1]:
                best = (q, cost)
        assert best is not None
        return {n: float(v) for n, v in zip(self.arm, best[0], strict=True)}, best[1]

    def _descend(
        self, q: np.ndarray, fixed: Mapping[str, float], want: Directions
    ) -> tuple[np.ndarray, float]:
        r = self._residual(q, fixed, want)
        damping = 1e-3
        for _ in range(ITERATIONS):
            jacobian = np.empty((r.size, q.size))
            for i in range(q.size):
                dq = np.zeros_like(q)
                dq[i] = STEP_DEG
                jacobian[:, i] = (self._residual(q + dq, fixed, want) - r) / STEP_DEG
            normal = jacobian.T @ jacobian
            step = np.linalg.solve(
                normal + damping * np.eye(q.size) * max(1e-9, float(np.trace(normal))),
                -jacobian.T @ r,
            )
            step = np.clip(step, -MAX_STEP_DEG, MAX_STEP_DEG)
            trial = np.clip(q + step, self.low, self.high)
            r_trial = self._residual(trial, fixed, want)
            if r_trial @ r_trial < r @ r:
                moved = float(np.max(np.abs(trial - q)))
                q, r = trial, r_trial
                damping = max(1e-6, damping / 3)
                if moved < 0.05:
                    break
            else:
                damping *= 10
                if damping > 1e3:
                    break
        return q, float(np.linalg.norm(r))
