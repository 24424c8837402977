"""The offscreen-OpenGL probe: a backend that fails or hangs is a one-line ConfigError."""

from __future__ import annotations

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
