"""PoppyEnv: the Gymnasium contract over a ``ServoWorld`` (spaces, actions, observations, render).

A task (reach, push a cube) subclasses it with what it adds to the world, how an episode
starts, what it shows in ``environment_state`` and how it rewards a step.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from poppy_core.errors import ArgumentError
from poppy_core.learning.envs.servo_world import ServoWorld
from poppy_core.sim.objects import ObjectSpec

OBS_TYPES = ("state", "pixels_agent_pos")
ACTION_TYPES = ("absolute", "delta")
POSITION_MARGIN_DEG = 5.0  # agent_pos bounds: the limits widened by this (joints press past them)
DEFAULT_CONTROL_HZ = 50.0  # the sync loop's rate on a real robot
DEFAULT_MAX_DELTA_DEG = 10.0  # a delta action's bound per step (per motor)
# agent_vel's and environment_state's bounds (values past them are clipped): ten times the
# fastest servo's no-load speed, and metres from the robot's base no task reaches
VELOCITY_BOUND_DPS = 7000.0
STATE_BOUND_M = 5.0


def _choice(value: str, allowed: Sequence[str], field: str) -> str:
    if value not in allowed:
        raise ArgumentError(f"{field} must be one of {', '.join(allowed)}, not {value!r}")
    return value


class PoppyEnv(gym.Env[dict[str, np.ndarray], np.ndarray]):
    """A Poppy robot in MuJoCo, one ``step`` per control period.

    Args:
        robot: the profile (``ergo-jr``, ``torso``).
        obs_type: ``"state"`` (``agent_pos``, ``agent_vel``, ``environment_state``) or
            ``"pixels_agent_pos"`` (the same and ``pixels``, the robot's camera).
        action_type: ``"absolute"``: each motor's goal (degrees, user frame, within its limits);
            ``"delta"``: degrees added to the last goals (each within ``max_delta_deg``).
        render_mode: None or ``"rgb_array"`` (``render()`` draws ``render_camera``).
        control_hz: steps per simulated second (each steps the physics 1/control_hz s).
        max_delta_deg: the bound of a delta action.
        camera: the MuJoCo camera of ``pixels`` (default the robot's own, ``camera``).
        observation_width, observation_height: the size of ``pixels``.
        render_camera: the camera ``render()`` draws (``front``, ``side``, ``top``, ``camera``).
        visualization_width, visualization_height: the size of ``render()``'s images.

    Raises:
        ArgumentError: an unknown obs_type, action_type, render_mode or camera, a bad number.
    """

    metadata: dict[str, Any] = {"render_modes": ["rgb_array"], "render_fps": 50}  # noqa: RUF012
    objects: ClassVar[tuple[ObjectSpec, ...]] = ()
    state_size: ClassVar[int] = 3

    def __init__(
        self,
        robot: str,
        *,
        obs_type: str = "state",
        action_type: str = "absolute",
        render_mode: str | None = None,
        control_hz: float = DEFAULT_CONTROL_HZ,
        max_delta_deg: float = DEFAULT_MAX_DELTA_DEG,
        camera: str = "camera",
        observation_width: int = 160,
        observation_height: int = 120,
        render_camera: str = "front",
        visualization_width: int = 640,
        visualization_height: int = 480,
    ) -> None:
        self.obs_type = _choice(obs_type, OBS_TYPES, "obs_type")
        self.action_type = _choice(action_type, ACTION_TYPES, "action_type")
        if render_mode is not None:
            _choice(render_mode, self.metadata["render_modes"], "render_mode")
        self.render_mode = render_mode
        if not control_hz > 0 or not max_delta_deg > 0:
            raise ArgumentError("control_hz and max_delta_deg must be positive")
        self.world = ServoWorld(robot, 1.0 / control_hz, self.objects)
        self.metadata = {**self.metadata, "render_fps": round(1.0 / self.world.control_period_s)}
        cameras = self.world.cameras()
        for name, field in ((camera, "camera"), (render_camera, "render_camera")):
            _choice(name, cameras, field)
        self.camera = camera
        self.pixels_size = (int(observation_width), int(observation_height))
        self.render_camera = render_camera
        self.render_size = (int(visualization_width), int(visualization_height))
        low, high = self.world.low.astype(np.float32), self.world.high.astype(np.float32)
        count = len(self.world.names)
        if self.action_type == "absolute":
            self.action_space = spaces.Box(low, high, dtype=np.float32)
        else:
            bound = np.float32(max_delta_deg)
            self.action_space = spaces.Box(-bound, bound, shape=(count,), dtype=np.float32)
        observed: dict[str, spaces.Space[Any]] = {
            "agent_pos": spaces.Box(
                low - POSITION_MARGIN_DEG, high + POSITION_MARGIN_DEG, dtype=np.float32
            ),
            "agent_vel": spaces.Box(
                -VELOCITY_BOUND_DPS, VELOCITY_BOUND_DPS, shape=(count,), dtype=np.float32
            ),
            "environment_state": spaces.Box(
                -STATE_BOUND_M, STATE_BOUND_M, shape=(self.state_size,), dtype=np.float32
            ),
        }
        if self.obs_type == "pixels_agent_pos":
            width, height = self.pixels_size
            observed["pixels"] = spaces.Box(0, 255, shape=(height, width, 3), dtype=np.uint8)
        self.observation_space = spaces.Dict(observed)  # type: ignore[assignment]
        self._pose_low = low - POSITION_MARGIN_DEG
        self._pose_high = high + POSITION_MARGIN_DEG
        self.pose = self.world.positions()
        """The motors' angles after the last reset or step (degrees, user frame)."""

    @property
    def motor_names(self) -> tuple[str, ...]:
        """The motors, in the order of actions and of ``agent_pos``."""
        return self.world.names

    # ------------------------------------------------------------------ the task's part

    def _start(self, rng: np.random.Generator) -> np.ndarray:
        """Set the episode's task up (targets, objects) and return the start pose."""
        raise NotImplementedError

    def _arrange(self) -> None:
        """Put the task's objects where ``_start`` drew them (after the world was reset)."""

    def _sense(self) -> None:
        """Measure what the reward and ``environment_state`` need (after every change of the
        world; ``self.pose`` holds the motors' angles already)."""

    def _environment_state(self) -> np.ndarray:
        """What ``environment_state`` shows (``state_size`` numbers)."""
        raise NotImplementedError

    def _evaluate(self) -> tuple[float, bool, dict[str, Any]]:
        """(reward, terminated, info) of the world now."""
        raise NotImplementedError

    # ------------------------------------------------------------------ Gymnasium

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        """A new episode: the task drawn from the env's generator (``seed`` reseeds it)."""
        super().reset(seed=seed)
        pose = self._start(self.np_random)
        self.world.reset(pose)
        self._arrange()
        self._measure()
        _, _, info = self._evaluate()
        return self._observation(), info

    def step(
        self, action: np.ndarray
    ) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        """Send the goals the action gives, step one control period, and score it."""
        move = np.asarray(action, dtype=float).reshape(-1)
        if move.shape != (len(self.world.names),) or not np.isfinite(move).all():
            raise ArgumentError(
                f"an action is {len(self.world.names)} finite numbers (one per motor: "
                f"{', '.join(self.world.names)}), not {action!r}"
            )
        if self.action_type == "delta":
            bound = float(self.action_space.high[0])  # type: ignore[attr-defined]
            move = self.world.goal + np.clip(move, -bound, bound)
        self.world.act(move)
        self._measure()
        reward, terminated, info = self._evaluate()
        return self._observation(), reward, terminated, False, info

    def _measure(self) -> None:
        self.pose = self.world.positions()
        self._sense()

    def _observation(self) -> dict[str, np.ndarray]:
        state = np.clip(self._environment_state(), -STATE_BOUND_M, STATE_BOUND_M)
        speed = np.clip(self.world.velocities(), -VELOCITY_BOUND_DPS, VELOCITY_BOUND_DPS)
        observation = {
            "agent_pos": np.clip(self.pose, self._pose_low, self._pose_high).astype(np.float32),
            "agent_vel": speed.astype(np.float32),
            "environment_state": state.astype(np.float32),
        }
        if self.obs_type == "pixels_agent_pos":
            width, height = self.pixels_size
            observation["pixels"] = self.world.render(self.camera, width, height)
        return observation

    def render(self) -> np.ndarray | None:
        """The world from ``render_camera`` (``render_mode="rgb_array"``), else None."""
        if self.render_mode != "rgb_array":
            return None
        width, height = self.render_size
        return self.world.render(self.render_camera, width, height)

    def close(self) -> None:
        """Free the renderers."""
        self.world.close()
        super().close()
