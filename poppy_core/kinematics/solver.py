"""Inverse kinematics: damped least squares (Levenberg-Marquardt) in joint limits, with restarts.

Each iteration solves ``(J J^T + lambda I) y = e`` and steps ``dq = J^T y``, where ``e`` is the
error of the tip (position, and the x axis or the whole rotation when asked) and ``J`` its
Jacobian. ``lambda`` falls after a step that lowers the error (towards Gauss-Newton, quadratic
convergence near the target) and rises after one that does not (towards a short gradient step).
Joint limits are kept by clipping; a joint at a limit that the error pushes further out is
taken out of ``J`` for that step, so the others do the work. When an attempt stalls short of the
target, the solver restarts from random joint angles within the limits (a fixed random
sequence: the same target always gives the same answer).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from poppy_core.kinematics.kernel import Kinematics
from poppy_core.kinematics.transforms import Matrix, rotation_log


@dataclass(frozen=True)
class SolverOptions:
    """How hard the solver tries and what it accepts.

    Attributes:
        tolerance_m: largest position error of an accepted solution.
        orientation_tolerance_deg: largest orientation error accepted (when one is asked).
        orientation_weight_m: metres of position error that weigh as much as one radian.
        max_iterations: iterations of one attempt.
        restarts: attempts from random joint angles after the first one fails.
        random_seed: seed of the random restarts.
    """

    tolerance_m: float = 1e-3
    orientation_tolerance_deg: float = 1.0
    orientation_weight_m: float = 0.1
    max_iterations: int = 60
    restarts: int = 20
    random_seed: int = 0


@dataclass(frozen=True, eq=False)
class Target:
    """Where the tip must go: a position (m) and optionally its x axis or whole rotation."""

    position: Matrix
    orientation: Matrix | None = None

    @property
    def mode(self) -> str:
        """``"position"``, ``"x"`` (the tip's x axis, pypot's vector orientation) or ``"all"``."""
        if self.orientation is None:
            return "position"
        return "x" if self.orientation.shape == (3,) else "all"


@dataclass(frozen=True, eq=False)
class Solution:
    """The best joint angles found and how close they bring the tip.

    Attributes:
        theta: joint angles (radians, the kinematic model's own angles), within the bounds.
        pose: the tip pose they give (4x4).
        position_error_m: distance from the target position.
        orientation_error_deg: angle to the target orientation (0 when none was asked).
        iterations: Jacobian evaluations over every attempt.
        attempts: attempts made (1 when the seed led to the target).
    """

    theta: Matrix
    pose: Matrix
    position_error_m: float
    orientation_error_deg: float
    iterations: int
    attempts: int


_LAMBDA_START = 1e-4
_LAMBDA_MIN = 1e-12
_LAMBDA_MAX = 1e3
_MAX_STEP_RAD = 0.6
_CONVERGED_M = 1e-6
_CONVERGED_RAD = 1e-5


def _errors(target: Target, pose: Matrix) -> tuple[float, float]:
    position = float(np.linalg.norm(target.position - pose[:3, 3]))
    if target.orientation is None:
        return position, 0.0
    if target.orientation.shape == (3,):
        cos = float(np.clip(pose[:3, 0] @ target.orientation, -1.0, 1.0))
        return position, math.degrees(math.acos(cos))
    angle = float(np.linalg.norm(rotation_log(target.orientation @ pose[:3, :3].T)))
    return position, math.degrees(angle)


class _Problem:
    """Residual and Jacobian of one target on one chain."""

    def __init__(self, kinematics: Kinematics, target: Target, weight: float) -> None:
        self.kinematics = kinematics
        self.target = target
        self.weight = weight

    def residual(self, theta: Matrix) -> tuple[Matrix, Matrix, Matrix]:
        """Error vector ``e``, Jacobian ``J`` (``e`` shrinks by ``J dq``) and the tip pose."""
        pose, jp, axes = self.kinematics.pose_jacobian(theta)
        error = self.target.position - pose[:3, 3]
        orientation = self.target.orientation
        if orientation is None:
            return error, jp, pose
        w = self.weight
        if orientation.shape == (3,):
            x = pose[:3, 0]
            rows = np.cross(axes.T, x).T
            return np.concatenate([error, w * (orientation - x)]), np.vstack([jp, w * rows]), pose
        turn = rotation_log(orientation @ pose[:3, :3].T)
        return np.concatenate([error, w * turn]), np.vstack([jp, w * axes]), pose


def _solve_normal(normal: Matrix, lam: float, error: Matrix) -> Matrix:
    """``(normal + lam I)^-1 error``; 3x3 systems (position targets) in closed form."""
    if error.shape[0] != 3:
        solved: Matrix = np.linalg.solve(normal + lam * np.eye(error.shape[0]), error).astype(float)
        return solved
    (a, b, c), (d, e, f), (g, h, i) = normal.tolist()
    a, e, i = a + lam, e + lam, i + lam
    x, y, z = error.tolist()
    ei_fh, fg_di, dh_eg = e * i - f * h, f * g - d * i, d * h - e * g
    det = a * ei_fh + b * fg_di + c * dh_eg
    return np.array(
        [
            (ei_fh * x + (c * h - b * i) * y + (b * f - c * e) * z) / det,
            (fg_di * x + (a * i - c * g) * y + (c * d - a * f) * z) / det,
            (dh_eg * x + (b * g - a * h) * y + (a * e - b * d) * z) / det,
        ]
    )


def _attempt(
    problem: _Problem, lower: Matrix, upper: Matrix, start: Matrix, max_iterations: int
) -> tuple[Matrix, Matrix, int]:
    """One Levenberg-Marquardt descent from ``start``: (angles, tip pose, iterations)."""
    theta = np.clip(start, lower, upper)
    error, jac, pose = problem.residual(theta)
    cost = float(error @ error)
    lam = _LAMBDA_START
    iterations = 1
    converged = _CONVERGED_M**2
    while iterations < max_iterations and cost > converged:
        free_jac = jac
        at_limit = (theta <= lower) | (theta >= upper)
        if at_limit.any():
            # a joint at a limit that the error pushes further out sits this step out
            gradient = jac.T @ error
            blocked = at_limit & (
                ((theta <= lower) & (gradient < 0)) | ((theta >= upper) & (gradient > 0))
            )
            if blocked.any():
                free_jac = jac.copy()
                free_jac[:, blocked] = 0.0
        normal = free_jac @ free_jac.T
        while True:
            step = free_jac.T @ _solve_normal(normal, lam, error)
            largest = float(np.abs(step).max())
            if largest > _MAX_STEP_RAD:
                step *= _MAX_STEP_RAD / largest
            candidate = np.minimum(np.maximum(theta + step, lower), upper)
            new_error, new_jac, new_pose = problem.residual(candidate)
            iterations += 1
            new_cost = float(new_error @ new_error)
            if new_cost < cost:
                lam = max(lam * 0.1, _LAMBDA_MIN)
                break
            lam *= 10.0
            if lam > _LAMBDA_MAX or iterations >= max_iterations:
                return theta, pose, iterations
        progress = cost - new_cost
        theta, error, jac, pose, cost = candidate, new_error, new_jac, new_pose, new_cost
        if progress < 1e-14 and lam <= _LAMBDA_START:
            break  # a flat spot: more iterations will not help
    return theta, pose, iterations


def solve(
    kinematics: Kinematics,
    target: Target,
    lower: Matrix,
    upper: Matrix,
    seed: Matrix,
    options: SolverOptions | None = None,
) -> Solution:
    """Joint angles within ``[lower, upper]`` that bring the tip to ``target``.

    Returns the best solution found, reached or not: the caller compares its errors with the
    tolerances (``accepted``). A target beyond the chain's reach gets a single attempt, which
    finds the nearest point.

    Args:
        kinematics: the chain (its active joints only).
        target: where the tip must go.
        lower: lower bounds of the joint angles (radians).
        upper: upper bounds.
        seed: the first attempt's start (clipped into the bounds).
        options: tolerances and effort; defaults when None.
    """
    opts = options or SolverOptions()
    problem = _Problem(kinematics, target, opts.orientation_weight_m)
    reach = float(np.linalg.norm(target.position - kinematics.fixed[0][:3, 3]))
    attempts = 1 if reach > kinematics.reach_bound_m() + opts.tolerance_m else 1 + opts.restarts
    rng: np.random.Generator | None = None  # made on the first restart: it costs ~50 µs
    best: Solution | None = None
    total = 0
    for attempt in range(attempts):
        if attempt == 0:
            start = seed
        else:
            rng = rng or np.random.default_rng(opts.random_seed)
            start = rng.uniform(lower, upper)
        theta, pose, iterations = _attempt(problem, lower, upper, start, opts.max_iterations)
        total += iterations
        position_error, orientation_error = _errors(target, pose)
        found = Solution(theta, pose, position_error, orientation_error, total, attempt + 1)
        if best is None or _score(found, opts) < _score(best, opts):
            best = found
        if accepted(best, opts):
            break
    assert best is not None
    return Solution(
        best.theta, best.pose, best.position_error_m, best.orientation_error_deg, total, attempt + 1
    )


def _score(solution: Solution, options: SolverOptions) -> float:
    return solution.position_error_m + options.orientation_weight_m * math.radians(
        solution.orientation_error_deg
    )


def accepted(solution: Solution, options: SolverOptions) -> bool:
    """True when the solution is within the options' tolerances."""
    return (
        solution.position_error_m <= options.tolerance_m
        and solution.orientation_error_deg <= options.orientation_tolerance_deg
    )
