"""Inverse kinematics benchmark: poppy's solver against ikpy as pypot uses it, same targets.

Targets: random joint configurations within the profile's angle limits (a fixed seed), their tip
positions as targets, so every one is reachable; every solver starts at the rest posture (every
joint at 0°, which is also where pypot's ``IKChain.goto`` starts ikpy). A solve succeeds when its
answer puts the tip within 1 mm of the target with every angle inside the limits (poppy's
forward kinematics judges both sides: it equals pypot's within 1e-9 m, see
tests/kinematics/test_forward.py). pypot runs in the peers venv (``bench/peers/pypot_ik.py``):
ikpy's default as ``IKChain.goto`` calls it (``max_iter=3``) and its accurate mode (no limit).
Unreachable targets: points 10 cm beyond the farthest reachable target from the first joint.

``POPPY_BENCH_IK_TARGETS`` (default 1000) sets the number of Ergo Jr targets (the Torso arm gets
a third of it): ikpy's accurate mode takes 0.3-0.4 s per target.
"""

from __future__ import annotations

import logging
import os
import statistics
import time
from typing import Any

import numpy as np

from bench.ik_peers import run_pypot_ik
from bench.registry import BenchContext, BenchResult, Table, register
from poppy_core.errors import KinematicsError
from poppy_core.kinematics import Chain

logger = logging.getLogger(__name__)

SUCCESS_M = 1e-3
LIMIT_SLACK_DEG = 1e-6
SUCCESS_GOAL = 0.995
SPEED_GOAL = 10.0
UNREACHABLE_M = 0.10
CASES = (("ergo-jr", "chain", 1.0), ("torso", "l_arm_chain", 1 / 3))
PEER_MODES = (("ikpy default (max_iter=3)", 3), ("ikpy accurate", None))
SEED = 2024


def _chain(kind: str, name: str) -> Chain:
    from poppy_core.motion.chains import chains_from_config
    from poppy_core.robot import load_profile

    return chains_from_config(load_profile(kind))[name]


def targets(chain: Chain, count: int, seed: int = SEED) -> list[list[float]]:
    """Tip positions of ``count`` random poses within the limits (passive joints at 0°)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        pose = {
            j.name: float(rng.uniform(*j.limits_deg)) if j.active else 0.0 for j in chain.joints
        }
        out.append([float(v) for v in chain.forward(pose)[:3, 3]])
    return out


def unreachable(chain: Chain, reachable: list[list[float]], count: int) -> list[list[float]]:
    """Points ``UNREACHABLE_M`` beyond the farthest reachable target, in random directions."""
    rest = chain.to_model(np.zeros(len(chain.joints)))
    active = [j.active for j in chain.joints]
    anchor = chain.kinematics.reduced(active, rest).fixed[0][:3, 3]  # on the first active axis
    radius = max(float(np.linalg.norm(np.array(p) - anchor)) for p in reachable) + UNREACHABLE_M
    rng = np.random.default_rng(SEED + 1)
    out = []
    for _ in range(count):
        direction = rng.normal(size=3)
        out.append([float(v) for v in anchor + radius * direction / np.linalg.norm(direction)])
    return out


def judge(chain: Chain, target: list[float], angles: dict[str, float]) -> tuple[float, bool]:
    """Position error (m) of an answer and whether its angles are within the limits."""
    limits = {j.name: j.limits_deg for j in chain.joints}
    inside = all(
        limits[n][0] - LIMIT_SLACK_DEG <= a <= limits[n][1] + LIMIT_SLACK_DEG
        for n, a in angles.items()
    )
    error = float(np.linalg.norm(chain.forward(angles)[:3, 3] - np.array(target)))
    return error, inside


def run_poppy(chain: Chain, points: list[list[float]]) -> dict[str, Any]:
    """poppy's solve of every target: errors, limits, times (raised targets have no answer)."""
    seed = chain.rest_deg
    errors: list[float | None] = []
    inside: list[bool] = []
    times: list[float] = []
    for target in points:
        start = time.perf_counter()
        try:
            angles: dict[str, float] | None = chain.solve(target, seed=seed)
        except KinematicsError:
            angles = None
        times.append(time.perf_counter() - start)
        if angles is None:
            errors.append(None)
            inside.append(True)
        else:
            error, ok = judge(chain, target, {**seed, **angles})
            errors.append(error)
            inside.append(ok)
    return {"errors": errors, "inside": inside, "times_s": times}


def run_peer(
    ctx: BenchContext,
    kind: str,
    name: str,
    chain: Chain,
    points: list[list[float]],
    max_iter: int | None,
) -> dict[str, Any] | None:
    """pypot's answers to the targets (None without the peers venv)."""
    if ctx.peers_python is None:
        return None
    job = {"job": "inverse", "chain": name, "targets": points, "max_iter": max_iter}
    try:
        answer = run_pypot_ik(ctx.peers_python, [kind], job)
    except RuntimeError as exc:
        logger.warning("pypot: %s", exc)
        return None
    errors: list[float | None] = []
    inside = []
    for target, joints in zip(points, answer["joints"], strict=True):
        error, ok = judge(chain, target, dict(zip(answer["motors"], joints, strict=True)))
        errors.append(error)
        inside.append(ok)
    return {"errors": errors, "inside": inside, "times_s": answer["times_s"]}


def rates(run: dict[str, Any]) -> dict[str, float]:
    """Success, accuracy, limit and timing figures of one solver's run."""
    errors, inside, times = run["errors"], run["inside"], run["times_s"]
    n = len(errors)
    close = [e is not None and e < SUCCESS_M for e in errors]
    return {
        "n": n,
        "success": sum(c and i for c, i in zip(close, inside, strict=True)) / n,
        "within_1mm": sum(close) / n,
        "limits_violated": sum(not i for i in inside) / n,
        "raised": sum(e is None for e in errors) / n,
        "median_s": statistics.median(times),
        "p99_s": float(np.percentile(times, 99)),
    }


def _pct(value: float) -> str:
    return f"{value * 100:.1f} %"


def _ms(value: float) -> str:
    return f"{value * 1000:.2f} ms" if value < 0.1 else f"{value * 1000:.0f} ms"


@register("ik", "inverse kinematics: poppy's solver vs ikpy as pypot uses it (same targets)")
def bench_ik(ctx: BenchContext) -> BenchResult:
    """Solve the same reachable and unreachable targets with poppy and with pypot's ikpy."""
    count = int(os.environ.get("POPPY_BENCH_IK_TARGETS", "1000"))
    result = BenchResult(name="ik", title="Inverse kinematics", intro=__doc__.split("\n\n")[1])
    raw: dict[str, Any] = {"targets": count}
    passed = True
    for kind, name, share in CASES:
        chain = _chain(kind, name)
        n = max(10, round(count * share))
        points = targets(chain, n)
        logger.info("%s %s: %d targets", kind, name, n)
        runs = {"poppy": rates(run_poppy(chain, points))}
        for label, max_iter in PEER_MODES:
            peer = run_peer(ctx, kind, name, chain, points, max_iter)
            if peer is not None:
                runs[label] = rates(peer)
        raw[f"{kind}/{name}"] = runs
        ours = runs["poppy"]
        rows = []
        for label, r in runs.items():
            speed = r["median_s"] / ours["median_s"]
            rows.append(
                [
                    label,
                    _pct(r["success"]),
                    _pct(r["within_1mm"]),
                    _pct(r["limits_violated"]),
                    _ms(r["median_s"]),
                    _ms(r["p99_s"]),
                    "1×" if label == "poppy" else f"{speed:.0f}× slower",
                ]
            )
        result.tables.append(
            Table(
                f"{kind} `{name}`: {n} reachable targets",
                [
                    "solver",
                    "success (< 1 mm, in limits)",
                    "within 1 mm",
                    "limits violated",
                    "median",
                    "p99",
                    "median vs poppy",
                ],
                rows,
            )
        )
        accurate = runs.get("ikpy accurate")
        goal_success = ours["success"] >= SUCCESS_GOAL
        goal_speed = accurate is None or (
            accurate["median_s"] >= SPEED_GOAL * ours["median_s"]
            and ours["success"] >= accurate["success"]
        )
        passed = passed and goal_success and goal_speed
        far = unreachable(chain, points, max(10, n // 5))
        beyond = {"poppy": run_poppy(chain, far)}
        default = run_peer(ctx, kind, name, chain, far, 3)
        if default is not None:
            beyond["ikpy default (max_iter=3)"] = default
        far_rows = []
        for label, run in beyond.items():
            r = rates(run)
            answered = [e for e in run["errors"] if e is not None]
            miss = f"{statistics.median(answered) * 100:.1f} cm" if answered else "-"
            far_rows.append([label, _pct(r["raised"]), _ms(r["median_s"]), miss])
            raw[f"{kind}/{name}/unreachable/{label}"] = r
        result.tables.append(
            Table(
                f"{kind} `{name}`: {len(far)} targets {UNREACHABLE_M * 100:.0f} cm out of reach",
                ["solver", "raised an error", "median", "median miss of the pose it returned"],
                far_rows,
            )
        )
        passed = passed and rates(beyond["poppy"])["raised"] == 1.0
    if ctx.peers_python is None:
        result.notes.append(f"pypot was not measured: {ctx.peers_note}.")
    result.notes += [
        f"Goals: success ≥ {SUCCESS_GOAL * 100:.1f} %; median ≥ {SPEED_GOAL:.0f}× faster than "
        "ikpy's accurate mode with at least its success; every unreachable target raises "
        "`KinematicsError` (never a wild pose).",
        "pypot gives ikpy the motors' angle limits converted with `rad2deg` although they are "
        'already degrees (pypot/creatures/ik.py), so ikpy\'s bounds are ±5000-8000 "radians": '
        "its answers ignore the limits, which the success column counts as failures. ikpy 3.0.1 "
        "also needs `numpy.float`, gone since numpy 1.24 (the cause of pypot's REST IK 500); "
        "the peer script restores the alias at run time.",
        "poppy: damped least squares (Levenberg-Marquardt) on numpy, limits by clipping with "
        "an active set, random restarts when a descent stalls; see docs/kinematics.md.",
    ]
    result.passed = passed
    result.raw = raw
    return result
