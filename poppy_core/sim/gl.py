"""Offscreen OpenGL: whether MuJoCo can render here, tried once in a child process."""

from __future__ import annotations

import os
import subprocess
import sys
import threading

from poppy_core.errors import ConfigError

PROBE_TIMEOUT_S = 30.0
GL_HELP = "install libegl1 libgl1 or libosmesa6 (`make sim-deps`) and set MUJOCO_GL=egl or osmesa"
# A one-geom scene drawn into a 16×16 buffer: what every renderer of ours does, in miniature.
_PROBE = (
    "import mujoco\n"
    "m = mujoco.MjModel.from_xml_string("
    "'<mujoco><worldbody><geom size=\"0.1\"/></worldbody></mujoco>')\n"
    "d = mujoco.MjData(m)\n"
    "mujoco.mj_forward(m, d)\n"
    "r = mujoco.Renderer(m, 16, 16)\n"
    "r.update_scene(d)\n"
    "r.render()\n"
    "r.close()\n"
)

_lock = threading.Lock()
_verdict: dict[str, str | None] = {}  # backend → None when it renders, else why not


def _try(backend: str, timeout_s: float) -> str | None:
    """None when ``backend`` renders in a child process, else a short reason."""
    env = dict(os.environ, MUJOCO_GL=backend)
    env.pop("PYOPENGL_PLATFORM", None)  # MuJoCo sets the one its backend needs
    try:
        done = subprocess.run(
            [sys.executable, "-c", _PROBE],
            env=env,
            capture_output=True,
            text=True,
            timeout=timeout_s,
            check=False,
        )
    except subprocess.TimeoutExpired:
        return f"it hung for {timeout_s:.0f} s"
    except OSError as exc:
        return str(exc)
    if done.returncode == 0:
        return None
    lines = [line for line in done.stderr.strip().splitlines() if line.strip()]
    return lines[-1].strip() if lines else f"exit code {done.returncode}"


def _known(backend: str, timeout_s: float) -> str | None:
    with _lock:
        if backend not in _verdict:
            _verdict[backend] = _try(backend, timeout_s)
        return _verdict[backend]


def _backend_mujoco_chose() -> str | None:
    """The backend mujoco chose when it was imported (glfw when unset), None if not yet."""
    module = sys.modules.get("mujoco.rendering.classic.gl_context") or sys.modules.get(
        "mujoco.gl_context"
    )
    chosen = getattr(module, "_MUJOCO_GL", None)
    return (chosen or "glfw") if isinstance(chosen, str) else None


def check_offscreen_gl(timeout_s: float = PROBE_TIMEOUT_S) -> None:
    """Return when MuJoCo can render offscreen with this process's ``MUJOCO_GL``.

    Some machines hang inside the OpenGL driver instead of failing (an EGL without a usable
    device), which no timeout in this process could interrupt; so the first render of a
    process is tried in a child, with a time limit, and the verdict is kept.

    Raises:
        ConfigError: rendering fails or hangs here; the message says what to install or set.
    """
    backend = os.environ.get("MUJOCO_GL", "glfw").lower()
    chosen = _backend_mujoco_chose()
    if chosen is not None and chosen != backend:
        raise ConfigError(
            f"mujoco was imported with MUJOCO_GL={chosen} and MUJOCO_GL is now "
            f"{backend}: import poppy_core (or set MUJOCO_GL) before importing mujoco",
            field="MUJOCO_GL",
        )  # the backend this process would use is not the one the probe tries
    reason = _known(backend, timeout_s)
    if reason is None:
        return
    others = [b for b in ("egl", "osmesa") if b != backend]
    working = next((b for b in others if _known(b, timeout_s) is None), None)
    advice = f"MUJOCO_GL={working} works here: set it" if working else GL_HELP
    raise ConfigError(
        f"offscreen rendering with MUJOCO_GL={backend} fails here ({reason}); {advice}",
        field="MUJOCO_GL",
    )


def working_backend(timeout_s: float = PROBE_TIMEOUT_S) -> str | None:
    """The first of this process's ``MUJOCO_GL``, ``egl``, ``osmesa`` that renders here."""
    first = os.environ.get("MUJOCO_GL", "").lower()
    candidates = [b for b in (first, "egl", "osmesa") if b]
    return next((b for b in dict.fromkeys(candidates) if _known(b, timeout_s) is None), None)


if __name__ == "__main__":  # `python -m poppy_core.sim.gl`: print a backend that works, if any
    found = working_backend()
    if found is None:
        print(f"no offscreen OpenGL here: {GL_HELP}", file=sys.stderr)
        sys.exit(1)
    print(found)
