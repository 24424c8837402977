"""SVT-AV1 makes the encoding threads SCHED_FIFO 99 when it can (as root): poppy puts them back,
so that an encoder never starves the robot's sync loop, nor hands its policy to the threads
and processes started after it."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import pytest

from poppy_core.dataset.video import AV1, pick_codec
from tests.helpers.no_real_time import without_real_time

CHILD = textwrap.dedent(
    """
    import json, os, sys
    from pathlib import Path
    import av
    import numpy as np
    from poppy_core.dataset.realtime import realtime_threads
    from poppy_core.dataset.video import AV1, Mp4File

    frame = np.random.default_rng(1).integers(0, 255, (480, 640, 3), np.uint8)
    folder = Path(sys.argv[1])
    if sys.argv[2] == "bare":  # PyAV alone: what SVT-AV1 does on this machine
        container = av.open(str(folder / "bare.mp4"), "w", format="mp4")
        stream = container.add_stream(AV1, rate=30)
        stream.width, stream.height, stream.pix_fmt = 640, 480, "yuv420p"
        for k in range(3):
            picture = av.VideoFrame.from_ndarray(frame, format="rgb24")
            picture.pts = k
            for packet in stream.encode(picture):
                container.mux(packet)
    else:
        video = Mp4File(folder / "poppy.mp4", 30, 640, 480, AV1)
        for _ in range(3):
            video.encode(frame)
    during = len(realtime_threads())
    spawned = []
    import threading
    thread = threading.Thread(target=lambda: spawned.append(os.sched_getscheduler(0)))
    thread.start()
    thread.join()
    print(json.dumps({"during": during, "caller": os.sched_getscheduler(0), "spawned": spawned[0]}))
    """
)


def encode_in_child(folder: Path, how: str, **popen: Any) -> dict[str, int]:
    done = subprocess.run(
        [sys.executable, "-c", CHILD, str(folder), how],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
        env={"SVT_LOG": "1", "PATH": "/usr/bin:/bin"},
        **popen,
    )
    return json.loads(done.stdout.splitlines()[-1])


@pytest.mark.skipif(pick_codec() != AV1, reason="this PyAV build has no SVT-AV1 encoder")
def test_an_av1_encoder_leaves_no_thread_real_time(tmp_path: Path) -> None:
    bare = encode_in_child(tmp_path, "bare")
    if bare["during"] == 0:
        pytest.skip("SVT-AV1 cannot make threads real-time here (not root): nothing to undo")
    assert bare["caller"] != 0 and bare["spawned"] != 0  # SCHED_FIFO, and inherited
    poppy = encode_in_child(tmp_path, "poppy")
    assert poppy == {"during": 0, "caller": 0, "spawned": 0}  # SCHED_OTHER everywhere


@pytest.mark.skipif(pick_codec() != AV1, reason="this PyAV build has no SVT-AV1 encoder")
def test_a_peer_started_without_real_time_encodes_at_the_normal_policy(tmp_path: Path) -> None:
    # how the tests start LeRobot's venv, whose encoder poppy does not mend
    bare = encode_in_child(tmp_path, "bare", preexec_fn=without_real_time)
    assert bare == {"during": 0, "caller": 0, "spawned": 0}
