"""MediaPipe Pose in a child process of its own venv (``poppy_core.sensors.pose`` runs it).

MediaPipe 0.10.21, the last release whose wheel ships a pose model (``solutions.pose``: the pose
detector and the full landmark model; the lite and heavy ones are downloaded at first use, so
they are not used here), pins numpy < 2 and protobuf < 5: it cannot live beside poppy's numpy 2
and Foxglove's protobuf, so it runs in the venv ``python -m poppy_core.sensors.pose_venv``
makes, as ``VENV/bin/python pose_worker.py [--static]``. This file imports only the standard
library, numpy and MediaPipe (never poppy).

The protocol, on stdin and stdout: the first line printed is ``{"ready": "<version>"}`` (or
``{"error": "..."}`` and exit 1). Each request is a JSON line ``{"width": W, "height": H}``
followed by W * H * 3 bytes of RGB pixels; each answer is one JSON line
``{"landmarks": [[x, y, z, visibility], ...], "world": [[x, y, z], ...]}`` with MediaPipe's 33
landmarks (``landmarks`` normalised to the image, ``world`` in metres from the hips' centre,
both x right and y down as the image), ``{"landmarks": null}`` when nobody is seen, or
``{"error": "..."}`` for a bad request.
"""

from __future__ import annotations

import json
import sys
from typing import Any


def _reply(out: Any, message: dict[str, Any]) -> None:
    out.write(json.dumps(message).encode() + b"\n")
    out.flush()


def _read_exact(stream: Any, size: int) -> bytes:
    chunks = []
    while size:
        chunk = stream.read(size)
        if not chunk:
            raise EOFError
        chunks.append(chunk)
        size -= len(chunk)
    return b"".join(chunks)


def main(argv: list[str]) -> int:
    """Serve requests until stdin closes."""
    out = sys.stdout.buffer
    try:
        import mediapipe  # type: ignore[import-not-found, unused-ignore]
        import numpy as np
        from mediapipe.python.solutions import pose  # type: ignore[import-not-found, unused-ignore]
    except Exception as exc:  # a venv without MediaPipe: say so on the protocol
        _reply(out, {"error": f"cannot import MediaPipe's pose: {exc}"})
        return 1
    estimator = pose.Pose(
        static_image_mode="--static" in argv,
        model_complexity=1,  # the full model, the one the wheel ships
        min_detection_confidence=0.5,
        min_tracking_confidence=0.5,
    )
    _reply(out, {"ready": mediapipe.__version__})
    stream = sys.stdin.buffer
    while True:
        line = stream.readline()
        if not line:
            return 0
        try:
            header = json.loads(line)
            width, height = int(header["width"]), int(header["height"])
            if not (0 < width <= 8192 and 0 < height <= 8192):
                raise ValueError(f"a frame of {width}x{height} pixels")
            pixels = _read_exact(stream, width * height * 3)
        except EOFError:
            return 0
        except (ValueError, KeyError, TypeError) as exc:
            _reply(out, {"error": f"bad request: {exc}"})
            continue
        image = np.frombuffer(pixels, dtype=np.uint8).reshape(height, width, 3)
        found = estimator.process(image)
        if found.pose_landmarks is None or found.pose_world_landmarks is None:
            _reply(out, {"landmarks": None})
            continue
        landmarks = [[p.x, p.y, p.z, p.visibility] for p in found.pose_landmarks.landmark]
        world = [[p.x, p.y, p.z] for p in found.pose_world_landmarks.landmark]
        _reply(out, {"landmarks": landmarks, "world": world})


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
