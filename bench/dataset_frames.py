"""The benchmark camera's frames (numpy only: the LeRobot peer imports it too).

A 640×480 scene that moves: smooth shapes and a grain over a gradient, sliding 4 pixels a frame
(black frames would flatter every encoder). Frame k is the same for poppy and its peer.
"""

from __future__ import annotations

import numpy as np

WIDTH, HEIGHT = 640, 480
STEP_PX = 4


class Scene:
    """``frame(k)``: the k-th RGB frame (height x width x 3, uint8)."""

    def __init__(self, width: int = WIDTH, height: int = HEIGHT, seed: int = 37) -> None:
        rng = np.random.default_rng(seed)
        wide = 2 * width
        x = np.linspace(0.0, 6 * np.pi, wide)[None, :]
        y = np.linspace(0.0, 2 * np.pi, height)[:, None]
        base = np.stack(
            [
                110 + 70 * np.sin(x + y),
                120 + 60 * np.cos(0.5 * x - y),
                100 + 50 * np.sin(0.3 * x * y / np.pi),
            ],
            axis=-1,
        )
        blocks = rng.integers(0, 60, size=(height // 16, wide // 16, 3))
        base += np.kron(blocks, np.ones((16, 16, 1)))[:height, :wide]
        base += rng.normal(0.0, 4.0, size=base.shape)  # sensor grain
        self._texture = np.clip(base, 0, 255).astype(np.uint8)
        self.width, self.height = width, height

    def frame(self, k: int) -> np.ndarray:
        shift = (k * STEP_PX) % self.width
        return np.ascontiguousarray(self._texture[:, shift : shift + self.width])
