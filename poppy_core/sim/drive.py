"""Drive: every bound motor's servo model as numpy arrays (targets, gains, sensed state)."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import Any

import mujoco  # noqa: TID253 (this room is imported lazily, by the factory)
import numpy as np

from poppy_core.sim.exchange import Command

# Below this, a goal counts as reached (rad); above this joint speed a motor is moving (°/s).
_REACHED_RAD = 1e-6
_MOVING_DPS = 2.0

# The ramp toward a goal is fed to MuJoCo in segments of at most this many steps (10 ms at the
# 2 ms timestep), each holding the mean of its per-step targets. mj_step releases the GIL, and
# every call may wait a whole thread switch interval (5 ms) to get it back while the bus and the
# sync loops run, so stepping one call per physics step cannot keep real time.
RAMP_SEGMENT_STEPS = 5

# Present speed: the joint's mean velocity over this last stretch of simulated time. The joint's
# instantaneous velocity jitters with each goal step of a goto or a primitive (sampled, it read
# +30 °/s on a joint going down at 75 °/s); a servo's speed register is a measured mean too.
SPEED_WINDOW_S = 0.1

State = tuple[float, float, float, bool]


@dataclass
class Joint:
    """Where one motor's joint and actuator are in the model, and its servo constants."""

    qpos: int
    dof: int
    actuator: int
    stall_nm: float
    kp: float
    kv: float


class Drive:
    """The servo loop of all bound motors, vectorised.

    Each physics step moves every driven actuator's target toward its goal at the motor's
    speed limit (a rate limit, as the moving speed register is); a compliant motor's target
    follows its joint and its gains are 0. Gains and force ranges are written into the model
    only when a command changed.
    """

    def __init__(self) -> None:
        self.joints: list[Joint] = []
        empty = np.zeros(0)
        self.qpos = self.dof = self.act = np.zeros(0, dtype=int)
        self.stall = self.kp = self.kv = empty
        self.target = self.goal = self.speed = self.torque_frac = empty
        self.on = np.zeros(0, dtype=bool)
        self._load_scale = empty
        self._dirty = True  # gains or force ranges to write into the model
        self._settled = False  # every target at its goal and in data.ctrl: nothing ramps
        self._sensed: deque[tuple[float, np.ndarray]] = deque()  # (sim time, joint angles)

    def add(self, joint: Joint, target_rad: float) -> int:
        """Add a motor's joint (compliant, target and goal ``target_rad``); returns its index."""
        self.joints.append(joint)
        self.qpos = np.append(self.qpos, joint.qpos)
        self.dof = np.append(self.dof, joint.dof)
        self.act = np.append(self.act, joint.actuator)
        self.stall = np.append(self.stall, joint.stall_nm)
        self.kp = np.append(self.kp, joint.kp)
        self.kv = np.append(self.kv, joint.kv)
        self.target = np.append(self.target, target_rad)
        self.goal = np.append(self.goal, target_rad)
        self.speed = np.append(self.speed, 1.0)
        self.torque_frac = np.append(self.torque_frac, 1.0)
        self.on = np.append(self.on, False)
        # sense(): the joint's angle is the motor's own (the model is built so)
        self._load_scale = 100.0 / self.stall
        self._dirty = True
        self._settled = False
        return len(self.joints) - 1

    def invalidate(self) -> None:
        """Write gains and force ranges again at the next :meth:`apply` (new model)."""
        self._dirty = True

    def relocate(self, index: int, qpos: int, dof: int, actuator: int) -> None:
        """Point joint ``index`` at new addresses (after the model was rebuilt)."""
        joint = self.joints[index]
        joint.qpos, joint.dof, joint.actuator = qpos, dof, actuator
        self.qpos[index], self.dof[index], self.act[index] = qpos, dof, actuator
        self._dirty = True

    def command(self, indexes: list[int], commands: list[Command], data: Any) -> None:
        """Take new commands (motor frame, degrees) for the motors at ``indexes``; a motor
        turning its torque on starts its ramp from where its joint is now."""
        if not indexes:
            return
        index = np.array(indexes)
        table = np.array(commands, dtype=float)  # columns: the Command fields
        on = table[:, 0] > 0.5
        fraction = np.minimum(np.maximum(table[:, 3] / 100.0, 0.0), 1.0)
        was_on = self.on[index]
        if (on != was_on).any() or (fraction != self.torque_frac[index]).any():
            self._dirty = True
            starting = index[on & ~was_on]
            self.target[starting] = data.qpos[self.qpos[starting]]
            self.on[index] = on
            self.torque_frac[index] = fraction
        self.goal[index] = np.radians(table[:, 1])
        self.speed[index] = np.radians(table[:, 2])
        self._settled = False

    def apply(self, model: Any) -> None:
        """Write gains and force ranges into ``model`` if a command changed since last time."""
        if not self._dirty or not self.joints:
            return
        act, on = self.act, self.on
        limit = self.stall * self.torque_frac
        model.actuator_forcerange[act, 0] = -limit
        model.actuator_forcerange[act, 1] = limit
        model.actuator_gainprm[act, 0] = np.where(on, self.kp, 0.0)
        model.actuator_biasprm[act, 1] = np.where(on, -self.kp, 0.0)
        model.actuator_biasprm[act, 2] = np.where(on, -self.kv, 0.0)
        self._dirty = False

    def step(self, model: Any, data: Any, steps: int) -> None:
        """Run ``steps`` physics steps, the driven targets ramping toward their goals.

        A compliant motor has no gain, so its target does not matter until its torque comes
        back on (:meth:`command` then puts it at the joint).
        """
        if steps <= 0:
            return
        if self._settled:
            mujoco.mj_step(model, data, nstep=steps)
            return
        target = self.target
        aim = np.where(self.on, self.goal, target)
        delta = aim - target
        if (np.abs(delta) <= self.speed * float(model.opt.timestep)).all():
            # Every goal within one step of rate limit: reached at the first step.
            target[:] = aim
            data.ctrl[self.act] = aim
            mujoco.mj_step(model, data, nstep=steps)
            self._settled = True
            return
        # The rate-limited ramp, RAMP_SEGMENT_STEPS at a time: each segment holds the mean of
        # its per-step targets, and the steps after every goal is reached go in one call.
        per_step = self.speed * float(model.opt.timestep)
        done, last = 0, target.copy()
        while done < steps and not self._settled:
            count = min(RAMP_SEGMENT_STEPS, steps - done)
            reach = np.arange(done + 1, done + count + 1)[:, None] * per_step
            rows = np.where(np.abs(delta) <= reach, aim, target + np.copysign(reach, delta))
            data.ctrl[self.act] = rows.mean(axis=0)
            mujoco.mj_step(model, data, nstep=count)
            done += count
            self._settled = bool((rows[-1] == aim).all())
            last = rows[-1]
        target[:] = last
        if done < steps:
            data.ctrl[self.act] = target
            mujoco.mj_step(model, data, nstep=steps - done)

    def set_target(self, index: int, target_rad: float) -> None:
        """Put motor ``index``'s target at ``target_rad`` (the joint was moved or reset)."""
        self.target[index] = target_rad
        self._settled = False

    def _mean_speed(self, now: float, position: np.ndarray, velocity: np.ndarray) -> np.ndarray:
        """Each joint's mean velocity (°/s) over the last ``SPEED_WINDOW_S`` of simulated time
        (its velocity now until that much time is sensed)."""
        sensed = self._sensed
        if sensed and (now < sensed[-1][0] or len(sensed[-1][1]) != len(position)):
            sensed.clear()  # the simulation was reset, or a motor added
        sensed.append((now, position.copy()))
        while len(sensed) > 1 and now - sensed[1][0] >= SPEED_WINDOW_S:
            sensed.popleft()
        then, before = sensed[0]
        if now - then < SPEED_WINDOW_S / 2:
            return velocity
        return np.asarray((position - before) / (now - then))

    def sense(self, data: Any) -> list[State]:
        """Each motor's (position °, speed °/s, load %, moving), in the motor's frame."""
        position = np.degrees(data.qpos[self.qpos])
        velocity = np.degrees(data.qvel[self.dof])
        speed = self._mean_speed(float(data.time), position, velocity)
        # e-manual: present load is a percentage of the maximum (stall) torque
        load = data.actuator_force[self.act] * self._load_scale
        load = np.minimum(np.maximum(load, -100.0), 100.0)
        moving = np.abs(velocity) > _MOVING_DPS
        if not self._settled:
            moving |= np.abs(self.goal - self.target) > _REACHED_RAD
        moving &= self.on
        return list(
            zip(position.tolist(), speed.tolist(), load.tolist(), moving.tolist(), strict=True)
        )
