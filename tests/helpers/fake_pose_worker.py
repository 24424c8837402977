"""A stand-in for MediaPipe's pose worker (``poppy_core/sensors/pose_worker.py``'s protocol):
every frame shows the same person, landmark i at (i / 40, i / 80) of the frame and at
(i, 2i, 3i) cm. Run by ``fake_pose_python`` in place of the pose venv's interpreter."""

from __future__ import annotations

import json
import sys


def main() -> int:
    out = sys.stdout.buffer
    out.write(json.dumps({"ready": "fake"}).encode() + b"\n")
    out.flush()
    landmarks = [[i / 40, i / 80, 0.0, 1.0] for i in range(33)]
    world = [[i / 100, 2 * i / 100, 3 * i / 100] for i in range(33)]
    stream = sys.stdin.buffer
    while True:
        line = stream.readline()
        if not line:
            return 0
        header = json.loads(line)
        size = int(header["width"]) * int(header["height"]) * 3
        while size:
            chunk = stream.read(size)
            if not chunk:
                return 0
            size -= len(chunk)
        out.write(json.dumps({"landmarks": landmarks, "world": world}).encode() + b"\n")
        out.flush()


if __name__ == "__main__":
    sys.exit(main())
