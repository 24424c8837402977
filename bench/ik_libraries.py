"""Measure the kinematics libraries poppy could build on (the numbers behind docs/kinematics.md).

Not a registered benchmark: it needs libraries poppy does not depend on. Run it in a scratch venv::

    python3 -m venv /tmp/ik-libs && /tmp/ik-libs/bin/pip install numpy mujoco pin mink pyyaml
    PYTHONPATH=. /tmp/ik-libs/bin/python bench/ik_libraries.py

For the Ergo Jr chain it times (1) one forward kinematics + position Jacobian with poppy's numpy
kernel, MuJoCo (``mj_kinematics`` + ``mj_comPos`` + ``mj_jacSite``) and pinocchio
(``computeFrameJacobian``), (2) a full solve of the same random reachable targets with poppy's
damped least squares solver over each of those three, (3) mink's differential IK (a QP per step,
daqp) iterated to 0.1 mm.
"""

from __future__ import annotations

import re
import statistics
import tempfile
import time
import timeit
from pathlib import Path
from typing import Any

import numpy as np

from poppy_core.kinematics import solver
from poppy_core.motion.chains import chains_from_config
from poppy_core.robot import load_profile

ROOT = Path(__file__).resolve().parent.parent
URDF = ROOT / "profiles" / "ergo-jr" / "poppy_ergo_jr.urdf"
MJCF = ROOT / "profiles" / "ergo-jr" / "model.xml"
TIP = [0.0, 0.0, -0.07]
TARGETS = 300
CALLS = 5000


class MujocoKinematics:
    """The ``Kinematics`` interface the solver uses, computed by MuJoCo (user angles)."""

    def __init__(self) -> None:
        import mujoco

        spec = mujoco.MjSpec.from_file(str(MJCF))
        spec.body("tip").add_site(name="tcp", pos=TIP)
        self.mj = mujoco
        self.model = spec.compile()
        self.data = mujoco.MjData(self.model)
        self.site = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, "tcp")
        self.jacp = np.zeros((3, self.model.nv))
        self.jacr = np.zeros((3, self.model.nv))
        self.fixed = np.array([np.eye(4)])

    def reach_bound_m(self) -> float:
        return 10.0

    def pose_jacobian(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        mj, data = self.mj, self.data
        data.qpos[:6] = theta
        mj.mj_kinematics(self.model, data)
        mj.mj_comPos(self.model, data)
        mj.mj_jacSite(self.model, data, self.jacp, self.jacr, self.site)
        pose = np.eye(4)
        pose[:3, :3] = data.site_xmat[self.site].reshape(3, 3)
        pose[:3, 3] = data.site_xpos[self.site]
        return pose, self.jacp[:, :6].copy(), self.jacr[:, :6].copy()


class PinocchioKinematics:
    """The same interface computed by pinocchio on the URDF (motor angles)."""

    def __init__(self, folder: Path) -> None:
        import pinocchio as pin

        # pinocchio models URDF "continuous" joints with (cos, sin): make them revolute
        text = URDF.read_text(encoding="utf-8").replace('type="continuous"', 'type="revolute"')
        text = re.sub(
            r'(<joint\s+name="m\d"\s+type="revolute">)',
            r'\1<limit lower="-3" upper="3" effort="1" velocity="1"/>',
            text,
        )
        path = folder / "ergo.urdf"
        path.write_text(text, encoding="utf-8")
        self.pin = pin
        self.model = pin.buildModelFromUrdf(str(path))
        placement = pin.SE3(np.eye(3), np.array(TIP))
        joint = self.model.getJointId("m6")
        frame = pin.Frame("tcp", joint, placement, pin.FrameType.OP_FRAME)
        self.frame = self.model.addFrame(frame)
        self.data = self.model.createData()
        self.fixed = np.array([np.eye(4)])

    def reach_bound_m(self) -> float:
        return 10.0

    def pose_jacobian(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        pin = self.pin
        jac = pin.computeFrameJacobian(
            self.model, self.data, theta, self.frame, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        )
        pin.updateFramePlacement(self.model, self.data, self.frame)
        placement = self.data.oMf[self.frame]
        pose = np.eye(4)
        pose[:3, :3] = placement.rotation
        pose[:3, 3] = placement.translation
        return pose, jac[:3].copy(), jac[3:].copy()


def main() -> int:
    """Print the per-call and per-solve figures."""
    chain = chains_from_config(load_profile("ergo-jr"))["chain"]
    signs = np.array([j.scale for j in chain.joints])  # URDF angle = sign * user angle here
    limits = np.radians(np.array([j.limits_deg for j in chain.joints]))
    rng = np.random.default_rng(3)
    poses = [rng.uniform(limits[:, 0], limits[:, 1]) for _ in range(TARGETS)]
    with tempfile.TemporaryDirectory() as tmp:
        backends: dict[str, tuple[Any, bool]] = {
            "poppy numpy kernel": (chain.kinematics, True),
            "MuJoCo": (MujocoKinematics(), False),
            "pinocchio": (PinocchioKinematics(Path(tmp)), True),
        }
        for name, (kin, motor_frame) in backends.items():
            scale = signs if motor_frame else np.ones(6)
            low = np.minimum(scale * limits[:, 0], scale * limits[:, 1])
            high = np.maximum(scale * limits[:, 0], scale * limits[:, 1])
            q = np.full(6, 0.3)
            per_call = timeit.timeit(lambda k=kin, q=q: k.pose_jacobian(q), number=CALLS) / CALLS
            times, ok = [], 0
            for pose in poses:
                target = solver.Target(kin.pose_jacobian(scale * pose)[0][:3, 3].copy())
                start = time.perf_counter()
                found = solver.solve(kin, target, low, high, np.clip(np.zeros(6), low, high))
                times.append(time.perf_counter() - start)
                ok += found.position_error_m < 1e-3
            print(
                f"{name:20s} FK+Jacobian {per_call * 1e6:6.1f} us   solve: success "
                f"{ok / TARGETS:.3f} median {statistics.median(times) * 1e3:5.2f} ms "
                f"p99 {np.percentile(times, 99) * 1e3:6.2f} ms"
            )
    mink_solve(poses[:100])
    return 0


def mink_solve(poses: list[np.ndarray]) -> None:
    """mink's differential IK iterated to 0.1 mm from the rest posture."""
    import mink
    import mujoco

    kin = MujocoKinematics()
    model = kin.model
    configuration = mink.Configuration(model)
    task = mink.FrameTask("tcp", "site", position_cost=1.0, orientation_cost=0.0)
    limits = [mink.ConfigurationLimit(model)]
    times, ok = [], 0
    for pose in poses:
        data = mujoco.MjData(model)
        data.qpos[:6] = pose
        mujoco.mj_kinematics(model, data)
        target = data.site_xpos[kin.site].copy()
        task.set_target(mink.SE3.from_rotation_and_translation(mink.SO3.identity(), target))
        configuration.update(np.zeros(model.nq))
        start = time.perf_counter()
        for _ in range(300):
            velocity = mink.solve_ik(
                configuration, [task], 0.05, "daqp", damping=1e-6, limits=limits
            )
            configuration.integrate_inplace(velocity, 0.05)
            if np.linalg.norm(configuration.data.site_xpos[kin.site] - target) < 1e-4:
                break
        times.append(time.perf_counter() - start)
        ok += np.linalg.norm(configuration.data.site_xpos[kin.site] - target) < 1e-3
    print(
        f"{'mink (daqp)':20s} solve: success {ok / len(poses):.3f} median "
        f"{statistics.median(times) * 1e3:5.2f} ms p99 {np.percentile(times, 99) * 1e3:6.2f} ms"
    )


if __name__ == "__main__":
    raise SystemExit(main())
