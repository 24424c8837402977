"""poppy_core.dataset writes LeRobotDataset v3.0 as LeRobot lays it out (read back without it)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import av
import numpy as np
import pyarrow.parquet as pq
import pytest

from poppy_core.dataset import feature_stats as stats
from poppy_core.dataset import layout
from poppy_core.dataset.layout import DatasetSpec
from poppy_core.dataset.reader import read_summary
from poppy_core.dataset.writer import DatasetWriter
from poppy_core.errors import ArgumentError

SPEC = DatasetSpec(30, ("m1", "m2", "m3"), {"top": (48, 64)}, "poppy_ergo_jr")


def frame(k: int) -> tuple[list[float], list[float], dict[str, np.ndarray]]:
    """Frame k of the test recordings: values the tests can predict."""
    image = np.zeros((48, 64, 3), np.uint8)
    image[..., 0] = (k * 7) % 256
    image[..., 1] = 100
    image[..., 2] = np.arange(64, dtype=np.uint8)[None, :] * 2
    return [k, -k, 0.5 * k], [k + 1, -k - 1, 0.5 * k + 1], {"top": image}


def record(root: Path, lengths: list[int], tasks: list[str] | None = None) -> DatasetWriter:
    writer = DatasetWriter.create(root, SPEC)
    for number, length in enumerate(lengths):
        writer.begin_episode((tasks or ["pick the cube"] * len(lengths))[number])
        for k in range(length):
            writer.add_frame(*frame(k))
        writer.save_episode()
    return writer


def test_layout_and_info(tmp_path: Path) -> None:
    root = tmp_path / "ds"
    record(root, [20, 25], ["pick the cube", "wave"])
    files = sorted(str(p.relative_to(root)) for p in root.rglob("*") if p.is_file())
    assert files == [
        "data/chunk-000/file-000.parquet",
        "data/chunk-000/file-001.parquet",
        "meta/episodes/chunk-000/file-000.parquet",
        "meta/info.json",
        "meta/stats.json",
        "meta/tasks.parquet",
        "videos/observation.images.top/chunk-000/file-000.mp4",
        "videos/observation.images.top/chunk-000/file-001.mp4",
    ]
    info = json.loads((root / "meta/info.json").read_text())
    assert info["codebase_version"] == "v3.0"
    assert (info["total_episodes"], info["total_frames"], info["total_tasks"]) == (2, 45, 2)
    assert info["splits"] == {"train": "0:2"}
    assert info["features"]["observation.state"] == {
        "dtype": "float32",
        "shape": [3],
        "names": ["m1.pos", "m2.pos", "m3.pos"],
        "unit": "degree",
    }
    video = info["features"]["observation.images.top"]
    assert video["shape"] == [48, 64, 3]
    assert video["info"]["video.pix_fmt"] == "yuv420p"
    assert video["info"]["video.codec"] in ("av1", "h264")
    assert list(info["features"])[-5:] == list(layout.DEFAULT_FEATURES)


def test_frames_tasks_and_episodes_tables(tmp_path: Path) -> None:
    root = tmp_path / "ds"
    record(root, [20, 25], ["pick the cube", "wave"])
    data = pq.read_table(root / "data/chunk-000/file-001.parquet").to_pydict()
    assert data["frame_index"] == list(range(25))
    assert data["index"] == list(range(20, 45))
    assert data["episode_index"] == [1] * 25
    assert data["task_index"] == [1] * 25
    assert data["timestamp"] == pytest.approx([k / 30 for k in range(25)])
    assert data["observation.state"][3] == [3.0, -3.0, 1.5]
    assert data["action"][3] == [4.0, -4.0, 2.5]
    tasks = pq.read_table(root / "meta/tasks.parquet")
    assert json.loads(tasks.schema.metadata[b"pandas"])["index_columns"] == ["__index_level_0__"]
    assert tasks.to_pydict() == {
        "task_index": [0, 1],
        "__index_level_0__": ["pick the cube", "wave"],
    }
    rows = pq.read_table(root / "meta/episodes/chunk-000/file-000.parquet").to_pylist()
    assert [(r["episode_index"], r["length"], r["tasks"]) for r in rows] == [
        (0, 20, ["pick the cube"]),
        (1, 25, ["wave"]),
    ]
    assert (rows[1]["dataset_from_index"], rows[1]["dataset_to_index"]) == (20, 45)
    assert rows[1]["videos/observation.images.top/to_timestamp"] == pytest.approx(25 / 30)
    assert rows[1]["stats/observation.state/max"] == [24.0, 0.0, 12.0]


def test_video_frames_at_k_over_fps(tmp_path: Path) -> None:
    root = tmp_path / "ds"
    record(root, [40])
    with av.open(str(root / "videos/observation.images.top/chunk-000/file-000.mp4")) as container:
        decoded = [(float(f.time), f.to_ndarray(format="rgb24")) for f in container.decode(video=0)]
    assert len(decoded) == 40
    for k, (time, image) in enumerate(decoded):
        assert time == pytest.approx(k / 30, abs=1e-9)
        assert abs(int(image[24, 32, 0]) - int(frame(k)[2]["top"][24, 32, 0])) <= 6


def test_stats_agree_with_numpy(tmp_path: Path) -> None:
    root = tmp_path / "ds"
    record(root, [20, 25])
    saved = stats.from_json(json.loads((root / "meta/stats.json").read_text()))
    states = np.array([frame(k)[0] for k in [*range(20), *range(25)]])
    state = saved["observation.state"]
    assert state["count"].tolist() == [45]
    assert state["min"] == pytest.approx(states.min(axis=0))
    assert state["max"] == pytest.approx(states.max(axis=0))
    assert state["mean"] == pytest.approx(states.mean(axis=0))
    assert state["std"] == pytest.approx(states.std(axis=0))
    assert set(state) == {"min", "max", "mean", "std", "count", "q01", "q10", "q50", "q90", "q99"}
    image = saved["observation.images.top"]
    assert image["mean"].shape == (3, 1, 1)
    assert image["mean"][1, 0, 0] == pytest.approx(100 / 255)
    assert image["max"][2, 0, 0] == pytest.approx(126 / 255)
    assert saved["index"]["max"].tolist() == [44]


def test_image_quantiles_are_numpys() -> None:
    rng = np.random.default_rng(3)
    gathered = stats.ImageStats()
    frames = [rng.integers(0, 256, (40, 50, 3), dtype=np.uint8) for _ in range(7)]
    for image in frames:
        gathered.add(image)
    result = gathered.result()
    pixels = np.concatenate([image.reshape(-1, 3) for image in frames]).astype(np.float64)
    for key, q in zip(stats.QUANTILE_KEYS, stats.QUANTILES, strict=True):
        assert result[key].reshape(3) == pytest.approx(np.quantile(pixels, q, axis=0) / 255)
    assert result["std"].reshape(3) == pytest.approx(pixels.std(axis=0) / 255)
    assert result["count"].tolist() == [7]


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda w: w.add_frame([float("nan"), 0, 0], [0, 0, 0], frame(0)[2]), "finite degrees"),
        (lambda w: w.add_frame([0, 0, 0], [1e9, 0, 0], frame(0)[2]), "finite degrees"),
        (lambda w: w.add_frame([0, 0], [0, 0, 0], frame(0)[2]), "2 values, not 3"),
        (lambda w: w.add_frame([0, 0, 0], [0, 0, 0], {"side": frame(0)[2]["top"]}), "each camera"),
        (
            lambda w: w.add_frame([0, 0, 0], [0, 0, 0], {"top": np.zeros((4, 4, 3), np.uint8)}),
            "not (48, 64, 3)",
        ),
    ],
)
def test_bad_frames_are_refused(tmp_path: Path, call, message: str) -> None:
    writer = DatasetWriter.create(tmp_path / "ds", SPEC)
    writer.begin_episode("task")
    with pytest.raises(ArgumentError, match=message.replace("(", r"\(").replace(")", r"\)")):
        call(writer)
    writer.close()


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: DatasetSpec(0, ("m1",)), "fps must be a whole number from 1 to 240, not 0"),
        (lambda: DatasetSpec(30, ("m1",), {"a/b": (48, 64)}), "cannot name a feature"),
        (lambda: layout.check_task("pick\nthe cube"), "control character"),
        (lambda: layout.check_task("pick\x1b[31m"), "control character"),
        (lambda: layout.check_repo_id("no-slash"), "user/name"),
    ],
)
def test_bad_specs_are_refused(make, message: str) -> None:
    with pytest.raises(ArgumentError, match=message):
        make()


def test_an_existing_root_is_refused(tmp_path: Path) -> None:
    (tmp_path / "ds").mkdir()
    with pytest.raises(ArgumentError, match="already exists: pass --resume"):
        DatasetWriter.create(tmp_path / "ds", SPEC)


def test_resume_adds_episodes_and_refuses_other_features(tmp_path: Path) -> None:
    root = tmp_path / "ds"
    record(root, [10]).close()
    writer = DatasetWriter.resume(root, SPEC)
    writer.begin_episode("wave")
    for k in range(5):
        writer.add_frame(*frame(k))
    assert writer.save_episode().index == 1
    summary = read_summary(root)
    assert [(e.index, e.frames) for e in summary.episodes] == [(0, 10), (1, 5)]
    assert summary.tasks == ("pick the cube", "wave")
    other = DatasetSpec(30, ("m1", "m2"), {"top": (48, 64)})
    with pytest.raises(ArgumentError, match="other features or another fps"):
        DatasetWriter.resume(root, other)


KILLED = textwrap.dedent(
    """
    import os, signal, sys, time
    sys.path.insert(0, {tests!r})
    from pathlib import Path
    from dataset.test_writer import SPEC, frame, record
    writer = record(Path({root!r}), [12, 9])
    writer.begin_episode("pick the cube")
    for k in range(30):
        writer.add_frame(*frame(k))
    video = writer._videos["top"].path
    for k in range(30, 3000):  # until the encoder has put bytes in its file (it buffers)
        if video.exists() and video.stat().st_size > 0:
            break
        writer.add_frame(*frame(k % 30))
        time.sleep(0.01)
    print("recording", flush=True)
    os.kill(os.getpid(), signal.SIGKILL)
    """
)


def killed_recording(root: Path) -> None:
    """Two episodes saved, the third killed (SIGKILL) once its video file has bytes."""
    tests = str(Path(__file__).resolve().parents[1])
    script = KILLED.format(tests=tests, root=str(root))
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=120, check=False
    )
    assert done.returncode == -signal.SIGKILL, done.stderr
    assert "recording" in done.stdout


def test_a_killed_recording_keeps_its_finished_episodes(tmp_path: Path) -> None:
    root = tmp_path / "ds"
    killed_recording(root)
    summary = read_summary(root)
    assert [(e.index, e.frames) for e in summary.episodes] == [(0, 12), (1, 9)]
    info = json.loads((root / "meta/info.json").read_text())
    assert (info["total_episodes"], info["total_frames"]) == (2, 21)
    assert sorted(p.name for p in (root / "data/chunk-000").iterdir()) == [
        "file-000.parquet",
        "file-001.parquet",
    ]
    # the encoder's process removes its file once its recorder is gone (its stdin ends); a
    # leftover of a machine that died is removed by resume
    leftovers = [p.name for p in root.rglob(".*") if p.is_file()]
    assert all(name.endswith(".recording") for name in leftovers)
    folder = root / "videos/observation.images.top/chunk-000"
    (folder / ".file-002.mp4.999999.recording").write_bytes(b"\0" * 100)
    writer = DatasetWriter.resume(root, SPEC)
    assert not [p for p in root.rglob(".*") if p.is_file()]
    writer.begin_episode("wave")
    writer.add_frame(*frame(0))
    assert writer.save_episode().index == 2
    assert os.path.exists(root / "videos/observation.images.top/chunk-000/file-002.mp4")


def test_a_robot_of_one_motor_is_recorded_and_read_back(tmp_path: Path) -> None:
    from poppy_core.dataset.rows import read_actions

    root = tmp_path / "ds"
    with DatasetWriter.create(root, DatasetSpec(30, ("m1",), {}, None)) as writer:
        writer.begin_episode("one joint")
        for k in range(5):
            writer.add_frame([float(k)], [k + 0.5])
        writer.save_episode()
    actions = read_actions(root, 0)
    assert actions.motors == ("m1",)
    assert actions.positions.tolist() == [[k + 0.5] for k in range(5)]
