"""`poppy dataset view --rerun`: an episode written as a Rerun recording and loaded back with
rerun-sdk's own reader: one scalar a motor and a frame for state and action, on the frame and
time timelines, the camera's frames as JPEG, the task; bad inputs refused in one line."""

from __future__ import annotations

import importlib.util
import io
import json
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("pyarrow")
if importlib.util.find_spec("rerun") is None:  # found, not imported: 0.7 s of CPU at collection
    pytest.skip("rerun-sdk is not installed (the rerun extra)", allow_module_level=True)

import av
import pyarrow as pa

from tests.dataset.test_view_mcap import FPS, FRAMES, MOTORS, action, state, write_dataset
from tests.helpers.cli import no_user_settings, run_poppy


@pytest.fixture(autouse=True)
def rrd_reader() -> Any:
    """rerun-sdk's RRD reader, imported by the tests that run (not at collection)."""
    return pytest.importorskip(
        "rerun.chunk", reason="this rerun-sdk has no RRD reader (rerun.chunk.RrdReader, 0.30+)"
    )


@pytest.fixture(autouse=True)
def settings(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("HF_LEROBOT_HOME", str(tmp_path / "lerobot"))
    return no_user_settings(tmp_path, monkeypatch)


@pytest.fixture
def dataset(tmp_path: Path) -> Path:
    root = tmp_path / "lerobot" / "me" / "wave"
    write_dataset(root)
    return root


def read_rrd(path: Path) -> dict[str, dict[str, list[Any]]]:
    """Each entity's columns (frame, time in ns and its components), rows in frame order."""
    from rerun import chunk

    reader = chunk.RrdReader(path)
    [entry] = reader.recordings()
    assert entry.application_id == "poppy"
    found: dict[str, dict[str, list[Any]]] = {}
    for piece in reader.stream():
        if piece.entity_path.startswith("/__"):
            continue
        batch = piece.to_record_batch()
        columns = found.setdefault(piece.entity_path.lstrip("/"), {})
        for name in batch.schema.names:
            column = batch.column(name)
            if pa.types.is_duration(column.type):  # as nanoseconds
                column = column.cast(pa.int64())
            if name != "rerun.controls.RowId":
                columns.setdefault(name, []).extend(column.to_pylist())
    for columns in found.values():
        if "frame" in columns:
            order = sorted(range(len(columns["frame"])), key=columns["frame"].__getitem__)
            for name, values in columns.items():
                columns[name] = [values[k] for k in order]
    return found


def test_an_episode_reads_back_from_its_rerun_file(dataset: Path, tmp_path: Path) -> None:
    out = tmp_path / "wave.rrd"
    result = run_poppy(
        "dataset", "view", "me/wave", "--episode", "1", "--rerun", str(out), "--json"
    )  # fmt: skip
    assert result.code == 0, result.stderr
    summary = json.loads(result.stdout)
    assert summary["rerun"] == str(out) and summary["frames"] == FRAMES
    assert out.read_bytes()[:4] == b"RRF2"
    found = read_rrd(out)
    expected = {f"{key}/{m}" for key in ("observation.state", "action") for m in MOTORS}
    assert set(found) == expected | {"observation.images.top", "task"}
    assert summary["rows"] == {entity: len(next(iter(c.values()))) for entity, c in found.items()}
    for i, motor in enumerate(MOTORS):
        for key, values in (("observation.state", state), ("action", action)):
            columns = found[f"{key}/{motor}"]
            assert columns["frame"] == list(range(FRAMES))
            assert columns["time"][0] == 0
            assert columns["time"][-1] == pytest.approx((FRAMES - 1) / FPS * 1e9, abs=1e3)
            got = [row[0] for row in columns["Scalars:scalars"]]
            assert got == pytest.approx([values(k)[i] for k in range(FRAMES)])
    assert found["task"]["TextDocument:text"] == [["wave"]]
    images = found["observation.images.top"]
    assert images["frame"] == list(range(FRAMES))
    assert images["EncodedImage:media_type"][0] == ["image/jpeg"]
    for k in (0, FRAMES - 1):
        blob = bytes(images["EncodedImage:blob"][k][0])
        with av.open(io.BytesIO(blob), format="mjpeg") as container:
            pixels = next(container.decode(video=0)).to_ndarray(format="rgb24")
        assert abs(int(pixels[24, 32, 0]) - 15 * k) <= 8, k


def test_both_exports_at_once_and_bad_ones_refused(dataset: Path, tmp_path: Path) -> None:
    mcap, rrd = tmp_path / "wave.mcap", tmp_path / "wave.rrd"
    rrd.write_bytes(b"mine")
    refused = run_poppy(
        "dataset", "view", "me/wave", "--episode", "1", "--mcap", str(mcap), "--rerun", str(rrd)
    )  # fmt: skip
    assert refused.code == 1, refused.stderr
    assert len(refused.stderr.strip().splitlines()) == 1 and "--force" in refused.stderr
    assert rrd.read_bytes() == b"mine" and not mcap.exists()  # checked before anything is written
    same = run_poppy(
        "dataset", "view", "me/wave", "--episode", "1", "--mcap", str(rrd), "--rerun", str(rrd)
    )  # fmt: skip
    assert same.code == 2 and "same file" in same.stderr, same.stderr
    done = run_poppy(
        "dataset", "view", "me/wave", "--episode", "0", "--mcap", str(mcap), "--rerun", str(rrd),
        "--force",
    )  # fmt: skip
    assert done.code == 0, done.stderr
    assert "MCAP for Foxglove" in done.stdout and "Rerun recording" in done.stdout
    assert len(read_rrd(rrd)["action/m1"]["frame"]) == 3
