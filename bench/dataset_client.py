"""poppy's side of ``python -m bench dataset``, in a process of its own (its CPU and memory alone).

``python -m bench.dataset_client ROOT SECONDS FPS``: an emulated Ergo Jr (sim: its sync loops at
50 Hz), a 640×480 camera of the moving scene (``bench.dataset_frames``), one episode of SECONDS
recorded by ``EpisodeRecorder`` (the robot by hand: the action is the next state). Prints one
JSON line of figures.
"""

from __future__ import annotations

import json
import resource
import statistics
import sys
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np

from bench.dataset_frames import HEIGHT, WIDTH, Scene
from poppy_core import from_config
from poppy_core.dataset.layout import DatasetSpec
from poppy_core.dataset.writer import DatasetWriter
from poppy_core.motion.episodes import ByHand, EpisodeRecorder, Progress
from poppy_core.robot import load_profile
from poppy_core.sensors.camera import Camera

SAMPLE_EVERY_S = 2.0


class SceneCamera(Camera):
    """The benchmark's camera: the moving scene, BGR as a camera gives it."""

    def __init__(self, name: str, fps: float) -> None:
        super().__init__(name, (WIDTH, HEIGHT), fps)
        self._scene = Scene()
        self._grabbed = 0

    def grab(self) -> np.ndarray:
        image = np.ascontiguousarray(self._scene.frame(self._grabbed)[..., ::-1])
        self._grabbed += 1
        return image


def _cpu_s() -> float:
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def _rss_mb() -> float:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return float("nan")


def main(root: Path, seconds: float, fps: int) -> dict[str, Any]:
    config = load_profile("ergo-jr")
    robot = from_config(config, sim=True, sensors=False)
    camera = SceneCamera("top", float(fps))
    motors = list(config.motors)
    sync_hz: list[float] = []
    rss_mb: list[float] = []
    last: list[Progress] = []
    next_sample = [0.0]

    def on_tick(progress: Progress) -> None:
        last[:] = [progress]
        if progress.elapsed_s < next_sample[0]:
            return
        next_sample[0] = progress.elapsed_s + SAMPLE_EVERY_S
        rss_mb.append(_rss_mb())
        rates = [
            loop.measured_hz
            for stats in robot.sync_stats().values()
            for loop in stats.loops.values()
            if loop.target_hz >= 50
        ]
        if rates and progress.elapsed_s > 1.0:
            sync_hz.append(min(rates))

    try:
        camera.frame  # noqa: B018 (waits for the first frame)
        spec = DatasetSpec(fps, tuple(motors), {"top": (HEIGHT, WIDTH)}, "ergo-jr")
        writer = DatasetWriter.create(root, spec)
        recorder = EpisodeRecorder(robot, writer, motors, {"top": camera}, ByHand(robot, motors))
        cpu_start = _cpu_s()
        start = time.perf_counter()
        saved = recorder.record(
            "bench", seconds, episode=0, stop=threading.Event(), on_tick=on_tick
        )
        done_s = time.perf_counter() - start
        writer.close()  # the encoder's process ends: its CPU is counted as a child's
        cpu_s = _cpu_s() - cpu_start
    finally:
        camera.close()
        robot.close()
    assert saved is not None
    size = sum(p.stat().st_size for p in root.rglob("*") if p.is_file())
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    dropped = last[0].dropped if last else 0
    return {
        "frames": saved.frames,
        "missed_ticks": max(0, dropped - saved.video_dropped),
        "video_dropped": saved.video_dropped,
        "loop_s": seconds,
        "save_s": max(0.0, done_s - seconds),
        "cpu_s": cpu_s,
        "max_rss_mb": own.ru_maxrss / 1024,
        "encoder_max_rss_mb": kids.ru_maxrss / 1024,
        "rss_first_mb": rss_mb[0] if rss_mb else None,
        "rss_last_mb": rss_mb[-1] if rss_mb else None,
        "sync_hz_min": min(sync_hz) if sync_hz else None,
        "sync_hz_median": statistics.median(sync_hz) if sync_hz else None,
        "bytes": size,
        "codec": writer.codec,
    }


if __name__ == "__main__":
    result = main(Path(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3]))
    sys.stdout.write(json.dumps(result) + "\n")
