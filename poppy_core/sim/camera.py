"""``SimCamera``: the MuJoCo scene rendered offscreen from the robot's own camera.

The profiles' models hold a camera named ``camera`` where the real one sits (Ergo Jr head,
Torso/Humanoid face; see ``looks.CAMERAS``). The camera renders in its own thread with its own
OpenGL context (EGL or OSMesa contexts belong to one thread): the scene is copied under the
world's lock, drawn outside it, so physics never waits for pixels. No shadows, reflections or
multisampling: on a software renderer they cost 30× the frame (see docs/sensors.md).
"""

from __future__ import annotations

import logging
from typing import Any, ClassVar

import mujoco  # noqa: TID253 (this room is imported lazily, by the factory)
import numpy as np

from poppy_core.errors import ConfigError, SensorError
from poppy_core.sensors.camera import DEFAULT_FPS, DEFAULT_RESOLUTION, Camera, CameraCalibration
from poppy_core.sensors.config import CameraMaker, SensorSpec
from poppy_core.sim.gl import GL_HELP, check_offscreen_gl

logger = logging.getLogger(__name__)

_OFF = (
    mujoco.mjtRndFlag.mjRND_SHADOW,
    mujoco.mjtRndFlag.mjRND_REFLECTION,
    mujoco.mjtRndFlag.mjRND_SKYBOX,
)


def camera_names(model: Any) -> list[str]:
    """Names of the cameras of a MuJoCo model."""
    names = (mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_CAMERA, i) for i in range(model.ncam))
    return [n for n in names if n]


class SimCamera(Camera):
    """A camera of a ``Simulation``: same registers and frames (BGR) as ``OpenCVCamera``.

    Args:
        name: the sensor's name.
        simulation: the world (``robot.simulation``).
        camera: the MuJoCo camera rendered (default: the sensor's name).
        resolution: ``(width, height)``.
        fps: frames per second rendered once started.

    Raises:
        SensorError: the model has no such camera, or the resolution exceeds its buffer.
    """

    registers: ClassVar[tuple[str, ...]] = (*Camera.registers, "index")

    def __init__(
        self,
        name: str,
        simulation: Any,
        camera: str | None = None,
        resolution: tuple[int, int] = DEFAULT_RESOLUTION,
        fps: float = DEFAULT_FPS,
    ) -> None:
        super().__init__(name, resolution, fps)
        self.simulation = simulation
        self._camera = camera or name
        model = simulation.model
        camera_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, self._camera)
        if camera_id < 0:
            known = ", ".join(camera_names(model)) or "none"
            raise SensorError(
                f"camera {name!r}: the simulation model has no camera {self._camera!r} "
                f"(cameras: {known}); set sim_camera in the sensor's config",
                sensor=name,
            )
        width, height = self._resolution
        limit = (int(model.vis.global_.offwidth), int(model.vis.global_.offheight))
        if width > limit[0] or height > limit[1]:
            raise SensorError(
                f"camera {name!r}: {width}x{height} is larger than the model's offscreen buffer "
                f"({limit[0]}x{limit[1]})",
                sensor=name,
            )
        fovy = float(model.cam_fovy[camera_id])
        self.calibration = CameraCalibration.from_fov(width, height, fovy)
        self._renderer: Any = None
        self._model: Any = None

    @property
    def index(self) -> str:
        """The MuJoCo camera rendered (where a real camera has its device)."""
        return self._camera

    def _make_renderer(self) -> None:
        sim = self.simulation
        width, height = self._resolution
        try:
            check_offscreen_gl()
        except ConfigError as exc:
            self.fail(str(exc))
            raise SensorError(f"camera {self.name!r}: {exc}") from exc
        with sim.lock:
            model = sim.view_model  # the drawn world (the robot's meshes)
            samples = int(model.vis.quality.offsamples)
            model.vis.quality.offsamples = 0  # read when the GL context is made
            try:
                self._renderer = mujoco.Renderer(model, height, width)
            except Exception as exc:
                self.fail(f"cannot render ({exc}): {GL_HELP}")
                raise SensorError(f"camera {self.name!r}: cannot render: {exc}") from exc
            finally:
                model.vis.quality.offsamples = samples
            self._model = model

    def grab(self) -> np.ndarray:
        sim = self.simulation
        with sim.lock:  # the model checked and posed at once: an object added between the two
            # would give the old model's renderer the new model's data
            if self._renderer is None or self._model is not sim.view_model:  # objects added
                self._close_renderer()
                self._make_renderer()
            renderer = self._renderer
            renderer.update_scene(sim.view(), camera=self._camera)
        for flag in _OFF:
            renderer.scene.flags[flag] = 0
        rgb = renderer.render()
        return np.ascontiguousarray(rgb[:, :, ::-1])  # OpenCV's BGR, as real cameras give

    def _close_renderer(self) -> None:
        if self._renderer is not None:
            try:
                self._renderer.close()
            except Exception:
                logger.debug("closing a renderer", exc_info=True)
            self._renderer = None

    def thread_ended(self) -> None:
        self._close_renderer()


def sim_camera_maker(simulation: Any) -> CameraMaker:
    """Makes the ``SimCamera`` of a config's camera entry (``sim_camera``: the MuJoCo camera)."""

    def make(spec: SensorSpec) -> Camera:
        return SimCamera(
            spec.name,
            simulation,
            spec.sim_camera or spec.name,
            spec.resolution or DEFAULT_RESOLUTION,
            spec.rate_hz or DEFAULT_FPS,
        )

    return make
