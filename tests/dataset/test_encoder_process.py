"""The videos are encoded in a process of their own: a recorder never waits for it; frames it
could not take are dropped, counted, and stood in for by the last one (a frame a row, at k/fps)."""

from __future__ import annotations

import gc
import os
import signal
from pathlib import Path

import av
import numpy as np
import pytest

from poppy_core.dataset.layout import DatasetSpec
from poppy_core.dataset.writer import DatasetWriter
from tests.helpers.waiting import eventually

FPS = 10  # a ring of max(4, fps) = 10 frames
SPEC = DatasetSpec(FPS, ("m1", "m2"), {"top": (48, 64)}, None)


def image(k: int) -> np.ndarray:
    picture = np.zeros((48, 64, 3), np.uint8)
    picture[..., 1] = 20 * k
    return picture


def decoded(path: Path) -> list[tuple[float, int]]:
    with av.open(str(path)) as container:
        return [
            (float(f.time), int(f.to_ndarray(format="rgb24")[24, 32, 1]))
            for f in container.decode(video=0)
        ]


def test_a_stalled_encoder_drops_frames_without_blocking(tmp_path: Path) -> None:
    root = tmp_path / "ds"
    writer = DatasetWriter.create(root, SPEC)
    try:
        writer.begin_episode("wait")
        worker = writer._encoders["top"]._proc
        assert worker.pid != os.getpid()
        os.kill(worker.pid, signal.SIGSTOP)  # the encoder stalls
        try:
            for k in range(12):
                writer.add_frame([k, 0], [k, 0], {"top": image(k)}, live=True)  # never waits
            assert writer.video_dropped == 2
        finally:
            os.kill(worker.pid, signal.SIGCONT)
        assert eventually(lambda: len(writer._encoders["top"]._free) == FPS, timeout_s=10)
        writer.add_frame([12, 0], [12, 0], {"top": image(12)}, live=True)
        saved = writer.save_episode()
    finally:
        writer.close()
    assert (saved.frames, saved.video_dropped) == (13, 2)
    frames = decoded(root / "videos/observation.images.top/chunk-000/file-000.mp4")
    assert [t for t, _ in frames] == pytest.approx([k / FPS for k in range(13)], abs=1e-9)
    greens = [g for _, g in frames]
    want = [20 * k for k in range(10)] + [180, 180, 240]  # 10 and 11 dropped: 9 stands in
    assert all(abs(g - w) <= 6 for g, w in zip(greens, want, strict=True)), greens
    assert worker.poll() is not None  # close ended the process


def test_a_writer_fed_faster_than_real_time_waits_and_drops_nothing(tmp_path: Path) -> None:
    root = tmp_path / "ds"
    with DatasetWriter.create(root, SPEC) as writer:
        writer.begin_episode("offline")
        for k in range(40):
            writer.add_frame([k, 0], [k, 0], {"top": image(k % 12)})
        saved = writer.save_episode()
    assert (saved.frames, saved.video_dropped) == (40, 0)
    frames = decoded(root / "videos/observation.images.top/chunk-000/file-000.mp4")
    assert [abs(g - 20 * (k % 12)) <= 6 for k, (_, g) in enumerate(frames)] == [True] * 40


def test_a_writer_dropped_without_close_ends_its_encoder(tmp_path: Path) -> None:
    writer = DatasetWriter.create(tmp_path / "ds", SPEC)
    writer.begin_episode("dropped")
    writer.add_frame([0, 0], [0, 0], {"top": image(0)})
    writer.save_episode()
    worker = writer._encoders["top"]._proc
    del writer
    gc.collect()
    assert eventually(lambda: worker.poll() is not None, timeout_s=10)
