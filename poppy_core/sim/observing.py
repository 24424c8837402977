"""What a MuJoCo world shows: bodies' names and poses, contacts, the drawn view, rendered images.

``Simulation`` takes these from ``Observing``; they read the world and change nothing in it
(but the renderers they keep, one per image size, freed by ``_close_renderers``).
"""

from __future__ import annotations

import threading
from typing import Any

import mujoco  # noqa: TID253 (this room is imported lazily, by the factory)
import numpy as np

from poppy_core.errors import ConfigError
from poppy_core.sim.gl import check_offscreen_gl


class Observing:
    """Reading the world's bodies, contacts and pictures (a ``Simulation`` mixin)."""

    model: Any
    view_model: Any
    data: Any
    _view_data: Any
    _renderers: dict[tuple[int, int], Any]
    _lock: threading.RLock

    def _body(self, name: str) -> int:
        index = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, name)
        if index < 0:
            known = ", ".join(self.body_names())
            raise ConfigError(f"no object {name!r} in the simulation ({known})", field=name)
        return int(index)

    def body_names(self) -> list[str]:
        """Names of the bodies (robot links and added objects)."""
        names = (
            mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_BODY, i)
            for i in range(1, self.model.nbody)
        )
        return [n for n in names if n]

    def get_object_position(self, name: str, relative_to: str | None = None) -> list[float]:
        """Position (m) of body ``name`` in the world, or in body ``relative_to``'s frame."""
        with self._lock:
            pos = np.array(self.data.xpos[self._body(name)])
            if relative_to is not None:
                ref = self._body(relative_to)
                rot = np.array(self.data.xmat[ref]).reshape(3, 3)
                pos = rot.T @ (pos - self.data.xpos[ref])
            return [float(v) for v in pos]

    def get_object_orientation(self, name: str, relative_to: str | None = None) -> list[float]:
        """Orientation quaternion (w, x, y, z) of body ``name`` (world or ``relative_to``)."""
        with self._lock:
            quat = np.array(self.data.xquat[self._body(name)])
            if relative_to is not None:
                inverse = np.zeros(4)
                mujoco.mju_negQuat(inverse, self.data.xquat[self._body(relative_to)])
                out = np.zeros(4)
                mujoco.mju_mulQuat(out, inverse, quat)
                quat = out
            return [float(v) for v in quat]

    def view(self) -> Any:
        """The drawn world's data at the physics' current pose (hold ``lock``): what a renderer
        of ``view_model`` shows."""
        data = self._view_data
        data.qpos[:] = self.data.qpos
        data.qvel[:] = self.data.qvel
        data.time = self.data.time
        mujoco.mj_kinematics(self.view_model, data)
        mujoco.mj_comPos(self.view_model, data)  # the cameras that follow the centre of mass
        mujoco.mj_camlight(self.view_model, data)
        return data

    def contacts(self) -> list[tuple[str, str]]:
        """Pairs of bodies touching now (each pair once, names sorted)."""
        with self._lock:
            pairs = set()
            for i in range(self.data.ncon):
                contact = self.data.contact[i]
                a = self.model.geom_bodyid[contact.geom[0]]
                b = self.model.geom_bodyid[contact.geom[1]]
                names = sorted(
                    mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_BODY, int(x)) or "world"
                    for x in (a, b)
                )
                pairs.add((names[0], names[1]))
            return sorted(pairs)

    def colliding(self, name: str, other: str | None = None) -> bool:
        """Whether body ``name`` touches ``other`` (any body when None; "world" is the floor)."""
        return any(name in pair and (other is None or other in pair) for pair in self.contacts())

    def render(self, camera: str | None = None, width: int = 640, height: int = 480) -> Any:
        """An RGB image (numpy array height × width × 3) from ``camera`` (default: free view).

        Raises:
            ConfigError: no OpenGL backend (set MUJOCO_GL to egl or osmesa).
        """
        check_offscreen_gl()
        with self._lock:
            key = (width, height)
            try:
                if key not in self._renderers:
                    self._renderers[key] = mujoco.Renderer(self.view_model, height, width)
                renderer = self._renderers[key]
                renderer.update_scene(self.view(), camera=camera if camera is not None else -1)
                return renderer.render()
            except (mujoco.FatalError, AttributeError, RuntimeError) as exc:
                raise ConfigError(
                    f"cannot render ({exc}): set MUJOCO_GL to egl or osmesa", field="MUJOCO_GL"
                ) from exc

    def _close_renderers(self) -> None:
        """Free the renderers (hold ``lock``): the world closes, or its model was rebuilt."""
        for renderer in self._renderers.values():
            renderer.close()
        self._renderers.clear()
