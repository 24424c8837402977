"""LeRobot's own writer at 30 fps, as ``lerobot-record`` drives it: run by the LeRobot venv.

``python lerobot_dataset_record.py ROOT SECONDS FPS``: one episode of SECONDS through
``LeRobotDataset.create/add_frame/save_episode/finalize`` (lerobot-record's defaults: PNG images
written by 4 threads per camera, then the video encoded by ``save_episode``), the same 640×480
scene as poppy's run (``bench/dataset_frames.py``) and six joints of synthetic state and action
(LeRobot drives no Poppy servo). Prints one JSON line of figures.
"""

from __future__ import annotations

import json
import math
import resource
import sys
import time
from pathlib import Path

import numpy as np
from lerobot.datasets.lerobot_dataset import LeRobotDataset

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from dataset_frames import HEIGHT, WIDTH, Scene

JOINTS = [f"m{i}.pos" for i in range(1, 7)]


def _cpu_s() -> float:
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def main(root: Path, seconds: float, fps: int) -> dict[str, object]:
    features = {
        "observation.state": {"dtype": "float32", "shape": (6,), "names": JOINTS},
        "action": {"dtype": "float32", "shape": (6,), "names": JOINTS},
        "observation.images.top": {
            "dtype": "video",
            "shape": (HEIGHT, WIDTH, 3),
            "names": ["height", "width", "channels"],
        },
    }
    scene = Scene()
    dataset = LeRobotDataset.create(
        "bench/lerobot-peer",
        fps,
        features,
        root=root,
        robot_type="ergo-jr",
        use_videos=True,
        image_writer_threads=4,
    )
    period = 1.0 / fps
    cpu_start = _cpu_s()
    start = time.perf_counter()
    deadline = start
    frames = missed = 0
    while deadline - start < seconds:
        now = time.perf_counter()
        if now < deadline:
            time.sleep(deadline - now)
            now = time.perf_counter()
        late = int((now - deadline) / period)  # ticks wholly past: skipped, as poppy's loop does
        missed += late
        deadline += late * period
        if deadline - start >= seconds:
            break
        angle = math.sin(2 * math.pi * 0.2 * (deadline - start))
        state = np.full(6, 30.0 * angle, dtype=np.float32)
        dataset.add_frame(
            {
                "observation.state": state,
                "action": state + 1.0,
                "observation.images.top": scene.frame(frames),
                "task": "bench",
            }
        )
        frames += 1
        deadline += period
    loop_s = time.perf_counter() - start
    save_start = time.perf_counter()
    dataset.save_episode()
    dataset.finalize()
    save_s = time.perf_counter() - save_start
    size = sum(p.stat().st_size for p in root.rglob("*") if p.is_file())
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return {
        "frames": frames,
        "missed_ticks": missed,
        "loop_s": loop_s,
        "save_s": save_s,
        "cpu_s": _cpu_s() - cpu_start,
        "max_rss_mb": max(own.ru_maxrss, kids.ru_maxrss) / 1024,
        "bytes": size,
    }


if __name__ == "__main__":
    result = main(Path(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3]))
    sys.stdout.write(json.dumps(result) + "\n")
