"""The offscreen-OpenGL probe: a backend that fails or hangs is a one-line ConfigError."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

pytest.importorskip("mujoco")

from poppy_core.errors import ConfigError
from poppy_core.sim import gl


@pytest.fixture(autouse=True)
def fresh_verdicts(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(gl, "_verdict", {})


def test_a_backend_that_does_not_exist_is_named_with_what_to_do(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(gl, "_backend_mujoco_chose", lambda: None)  # mujoco not imported yet
    monkeypatch.setenv("MUJOCO_GL", "nosuchgl")
    with pytest.raises(ConfigError) as caught:
        gl.check_offscreen_gl(timeout_s=60)
    message = str(caught.value)
    assert "MUJOCO_GL=nosuchgl" in message
    assert "\n" not in message
    assert "works here" in message or "libosmesa6" in message


def test_a_renderer_that_hangs_is_stopped_and_reported(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(gl, "_PROBE", "import time; time.sleep(30)")
    monkeypatch.setenv("MUJOCO_GL", "egl")
    with pytest.raises(ConfigError, match=r"hung for 1 s"):
        gl.check_offscreen_gl(timeout_s=1)


def test_the_verdict_is_kept(monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[str] = []
    monkeypatch.setattr(gl, "_try", lambda backend, timeout_s: calls.append(backend))
    monkeypatch.setenv("MUJOCO_GL", "egl")
    gl.check_offscreen_gl()
    gl.check_offscreen_gl()
    assert calls == ["egl"]


def test_mujoco_imported_with_another_backend_is_an_error_not_a_hang(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(gl, "_backend_mujoco_chose", lambda: "glfw")
    monkeypatch.setenv("MUJOCO_GL", "egl")
    with pytest.raises(ConfigError, match="before importing mujoco") as caught:
        gl.check_offscreen_gl()
    assert "\n" not in str(caught.value)


def test_importing_poppy_core_first_sets_the_headless_backend() -> None:
    """A script without a display that imports poppy_core, then mujoco, renders with EGL."""
    code = (
        "import poppy_core, mujoco, os\n"
        "from mujoco.rendering.classic import gl_context\n"
        "print(os.environ['MUJOCO_GL'], gl_context._MUJOCO_GL)\n"
    )
    env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "DISPLAY")}
    done = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["egl", "egl"]
