"""`poppy dataset view --mcap`: an episode written as an MCAP file, read back with the mcap
package: every channel decodes, one message per frame on the frame channels, stamped with the
dataset's timestamps; state and action in radians through the profile's orientations; the
camera's frames as JPEG; bad inputs refused in one line."""

from __future__ import annotations

import io
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip("pyarrow")
pytest.importorskip("foxglove")
pytest.importorskip("mcap_protobuf")

import av
from mcap.reader import make_reader

from poppy_core.dataset.layout import DatasetSpec
from poppy_core.dataset.writer import DatasetWriter
from tests.foxglove_app.test_foxglove_server import orientation_signs
from tests.foxglove_app.test_mcap import read_back
from tests.helpers.cli import no_user_settings, run_poppy

MOTORS = tuple(f"m{i}" for i in range(1, 7))
FPS = 10
FRAMES = 14
FRAME_TOPICS = ("/joint_states", "/action", "/tf", "/top/image")
ONCE_TOPICS = ("/robot_description", "/robot_model", "/task")


@pytest.fixture(autouse=True)
def settings(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("HF_LEROBOT_HOME", str(tmp_path / "lerobot"))
    return no_user_settings(tmp_path, monkeypatch)


def state(k: int) -> list[float]:
    return [2.0 * k, -k, 0.0, 10.0, -20.0, 0.5 * k]


def action(k: int) -> list[float]:
    return [value + 1.0 for value in state(k)]


def image(k: int) -> np.ndarray:
    picture = np.zeros((48, 64, 3), np.uint8)
    picture[..., 0] = 15 * k
    picture[..., 1] = 100
    return picture


def write_dataset(root: Path, robot_type: str | None = "ergo-jr") -> None:
    """Episode 0: 3 still frames (task "stay"); episode 1: FRAMES frames (task "wave")."""
    spec = DatasetSpec(FPS, MOTORS, {"top": (48, 64)}, robot_type)
    with DatasetWriter.create(root, spec) as writer:
        writer.begin_episode("stay")
        for _ in range(3):
            writer.add_frame(state(0), state(0), {"top": image(0)})
        writer.save_episode()
        writer.begin_episode("wave")
        for k in range(FRAMES):
            writer.add_frame(state(k), action(k), {"top": image(k)})
        writer.save_episode()


@pytest.fixture
def dataset(tmp_path: Path) -> Path:
    root = tmp_path / "lerobot" / "me" / "wave"
    write_dataset(root)
    return root


def log_times(path: Path) -> dict[str, list[int]]:
    times: dict[str, list[int]] = {}
    with path.open("rb") as stream:
        for _, channel, message in make_reader(stream).iter_messages(log_time_order=True):
            times.setdefault(channel.topic, []).append(message.log_time)
    return times


def positions(message: Any) -> dict[str, float]:
    return {joint.name: joint.position for joint in message.joints}


def test_an_episode_reads_back_from_its_mcap_file(dataset: Path, tmp_path: Path) -> None:
    out = tmp_path / "wave.mcap"
    result = run_poppy("dataset", "view", "me/wave", "--episode", "1", "--mcap", str(out), "--json")
    assert result.code == 0, result.stderr
    summary = json.loads(result.stdout)
    assert summary["frames"] == FRAMES and summary["mcap"] == str(out)
    decoded = read_back(out)
    assert set(decoded) == {*FRAME_TOPICS, *ONCE_TOPICS}
    for topic in FRAME_TOPICS:
        assert len(decoded[topic]) == FRAMES, topic
    for topic in ONCE_TOPICS:
        assert len(decoded[topic]) == 1, topic
    assert summary["messages"] == {topic: len(found) for topic, found in decoded.items()}
    times = log_times(out)
    for topic in FRAME_TOPICS:
        assert times[topic][0] == 0, topic
        assert times[topic][-1] == pytest.approx((FRAMES - 1) / FPS * 1e9, abs=1e3), topic
        assert times[topic] == sorted(times[topic])

    signs = orientation_signs()
    for k in (0, 5, FRAMES - 1):
        got_state = positions(decoded["/joint_states"][k])
        got_action = positions(decoded["/action"][k])
        for i, motor in enumerate(MOTORS):
            assert got_state[motor] == pytest.approx(math.radians(signs[motor] * state(k)[i]))
            assert got_action[motor] == pytest.approx(math.radians(signs[motor] * action(k)[i]))
        assert decoded["/joint_states"][k].timestamp.ToNanoseconds() == times["/action"][k]

    # the model: the URDF and its meshes embedded; /tf names the URDF's links
    assert "<robot" in decoded["/robot_description"][0]["data"]
    entities = decoded["/robot_model"][0].entities
    assert entities and all(model.data for e in entities for model in e.models)
    links = {t.child_frame_id for t in decoded["/tf"][0].transforms}
    assert {e.frame_id for e in entities} <= links | {"base_link"}
    assert "episode 1: wave" in decoded["/task"][0].message

    # the camera: JPEG frames, frame k's picture at frame k's time
    for k in (0, 7, FRAMES - 1):
        picture = decoded["/top/image"][k]
        assert picture.format == "jpeg" and picture.frame_id == "top"
        with av.open(io.BytesIO(picture.data), format="mjpeg") as container:
            pixels = next(container.decode(video=0)).to_ndarray(format="rgb24")
        assert pixels.shape == (48, 64, 3)
        assert abs(int(pixels[24, 32, 0]) - 15 * k) <= 8, k


def test_a_dataset_of_an_unknown_robot_gets_degrees_as_radians(tmp_path: Path) -> None:
    root = tmp_path / "lerobot" / "me" / "other"
    write_dataset(root, robot_type="a-robot-of-mine")
    out = tmp_path / "other.mcap"
    result = run_poppy("dataset", "view", "me/other", "--episode", "0", "--mcap", str(out))
    assert result.code == 0, result.stderr
    assert "no robot model" in result.stderr and "--profile" in result.stderr
    decoded = read_back(out)
    assert set(decoded) == {"/joint_states", "/action", "/task", "/top/image"}
    assert positions(decoded["/joint_states"][0])["m4"] == pytest.approx(math.radians(10.0))
    # --profile gives the model
    again = run_poppy(
        "dataset", "view", "me/other", "--episode", "0", "--mcap", str(out), "--force",
        "--profile", "ergo-jr",
    )  # fmt: skip
    assert again.code == 0, again.stderr
    assert "/robot_model" in read_back(out)


@pytest.mark.parametrize(
    ("args", "code", "message"),
    [
        (("--episode", "2"), 2, "no episode 2 in this dataset (episodes: 0 to 1)"),
        (("--episode", "1", "--root", "/nonexistent/ds"), 2, "holds no dataset"),
        (("--episode", "9", "--no-mcap"), 2, "no episode 9 in this dataset (episodes: 0 to 1)"),
        (("--no-mcap", "--force"), 2, "--force replaces an exported file"),
        (("--rerun", "/tmp/never.rrd"), 2, "give --episode K"),
        (("--episode", "1", "--profile", "ergo-jx"), 1, "did you mean ergo-jr"),
        (("--episode", "1", "--mcap", "/nonexistent/folder/x.mcap"), 1, "/nonexistent/folder"),
    ],
)
def test_bad_views_are_refused_in_one_line(
    dataset: Path, tmp_path: Path, args: tuple[str, ...], code: int, message: str
) -> None:
    given = [a for a in args if a != "--no-mcap"]
    if "--mcap" not in args and "--no-mcap" not in args:
        given += ["--mcap", str(tmp_path / "x.mcap")]
    result = run_poppy("dataset", "view", "me/wave", *given)
    assert result.code == code, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], result.stderr
    assert not (tmp_path / "x.mcap").exists()


def test_an_existing_file_is_kept_without_force(dataset: Path, tmp_path: Path) -> None:
    out = tmp_path / "wave.mcap"
    out.write_bytes(b"mine")
    result = run_poppy("dataset", "view", "me/wave", "--episode", "1", "--mcap", str(out))
    assert result.code == 1, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "--force" in lines[0], result.stderr
    assert out.read_bytes() == b"mine"
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []
    replaced = run_poppy(
        "dataset", "view", "me/wave", "--episode", "1", "--mcap", str(out), "--force"
    )
    assert replaced.code == 0, replaced.stderr
    assert len(read_back(out)["/joint_states"]) == FRAMES
