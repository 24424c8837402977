"""`poppy record --mcap FILE` and ``McapRecording``: the file is read back with the mcap package
and every channel decodes (protobuf with the schema the file holds, JSON); the joint positions
are the motors' angles in radians."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("foxglove")
pytest.importorskip("mcap_protobuf")

from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

from poppy_core import from_profile
from poppy_core.errors import FileError
from poppy_core.motion.move_format import read_move
from poppy_core.server.foxglove import McapRecording
from tests.foxglove_app.test_foxglove_server import URDF, orientation_signs
from tests.helpers.cli import run_poppy
from tests.helpers.waiting import eventually

TOPICS = {
    "/joint_states",
    "/tf",
    "/robot_description",
    "/health",
    "/camera/image",
    "/camera/detections",
    "/robot_model",
}


def read_back(path: Path) -> dict[str, list[Any]]:
    """Every message of the file decoded, by topic (a channel that does not decode fails)."""
    factory = DecoderFactory()
    decoded: dict[str, list[Any]] = {}
    with path.open("rb") as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        assert summary is not None  # a finished file: its summary and index are written
        for channel in summary.channels.values():
            decoded.setdefault(channel.topic, [])
        for schema, channel, message in reader.iter_messages(log_time_order=True):
            if channel.message_encoding == "json":
                assert schema is not None and schema.encoding == "jsonschema"
                value = json.loads(message.data)
            else:
                decode = factory.decoder_for(channel.message_encoding, schema)
                assert decode is not None, (channel.topic, channel.message_encoding)
                value = decode(message.data)
            decoded[channel.topic].append(value)
    return decoded


def test_a_recording_reads_back_with_every_channel_decoded(tmp_path: Path) -> None:
    path = tmp_path / "take.mcap"
    robot = from_profile("ergo-jr", sim=True)
    try:
        robot.sensor("marker_detector").start()
        robot.compliant = False
        robot.motor("m1").goal_position = 25.0
        robot.motor("m5").goal_position = -15.0
        assert eventually(lambda: abs(robot.motor("m1").present_position - 25.0) < 0.5, 20.0)
        assert eventually(lambda: abs(robot.motor("m5").present_position + 15.0) < 0.5, 20.0)
        recording = McapRecording(robot, path, "jr1", state_rate_hz=20.0).start()
        try:
            assert set(recording.topics) == TOPICS
            assert eventually(lambda: recording.publisher.published >= 10, 30.0)
            camera = recording.publisher.cameras["camera"][0]
            assert eventually(lambda: camera.running and camera.latest().number > 3, 30.0)
        finally:
            written = recording.stop()
        positions = {m.name: m.present_position for m in robot.motors}
    finally:
        robot.close()
    assert written == path
    assert not list(tmp_path.glob(".*.tmp"))  # the temporary file is gone
    decoded = read_back(path)
    assert set(decoded) == TOPICS
    assert all(decoded[t] for t in TOPICS), {t: len(v) for t, v in decoded.items()}
    assert decoded["/robot_description"][0]["data"] == URDF.read_text()
    signs = orientation_signs()
    last = decoded["/joint_states"][-1]
    for joint in last.joints:
        expected = math.radians(signs[joint.name] * positions[joint.name])
        assert joint.position == pytest.approx(expected, abs=0.01)
    assert {j.name: j.position for j in last.joints}["m1"] == pytest.approx(
        math.radians(25.0), abs=0.01
    )
    assert {t.child_frame_id for t in decoded["/tf"][-1].transforms} >= {"long_U", "tip"}
    assert decoded["/camera/image"][0].data[:2] == b"\xff\xd8"
    [scene] = decoded["/robot_model"]  # the meshes, embedded once (a file has no server)
    urdf_meshes = {
        line.split('"')[1].rsplit("/", 1)[1]
        for line in URDF.read_text().splitlines()
        if "package://" in line
    }
    frames = {e.frame_id for e in scene.entities}
    assert frames == {"base_link", "long_U", "section_1", "section_2", "section_3"} | {
        "section_4",
        "tip",
    }
    embedded = {m.data for e in scene.entities for m in e.models}
    assert embedded == {(URDF.parent / "meshes" / n).read_bytes() for n in urdf_meshes}
    assert {m.media_type for e in scene.entities for m in e.models} == {"model/stl"}
    assert all(e.frame_locked for e in scene.entities)
    assert any(line.message.startswith("bus ") for line in decoded["/health"])


def test_an_existing_file_is_refused_before_anything_runs(tmp_path: Path) -> None:
    path = tmp_path / "take.mcap"
    path.write_bytes(b"mine")
    robot = from_profile("ergo-jr", sim=True, sensors=False)
    try:
        with pytest.raises(FileError, match="exists"):
            McapRecording(robot, path, "jr1")
    finally:
        robot.close()
    assert path.read_bytes() == b"mine"


def test_poppy_record_mcap_writes_a_file_foxglove_opens(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    target = tmp_path / "take.mcap"
    done = run_poppy(
        "record",
        "wave",
        "-o",
        str(tmp_path),
        "--mcap",
        str(target),
        "--duration",
        "1.5",
        "--freq",
        "20",
        "--sim",
        "--profile",
        "ergo-jr",
        "--json",
    )
    assert done.code == 0, done
    summary = done.json()
    assert summary["mcap"] == str(target)
    move = read_move(summary["path"])
    decoded = read_back(target)
    assert {"/joint_states", "/tf", "/robot_description", "/health"} <= set(decoded)
    assert all(decoded[t] for t in ("/joint_states", "/tf", "/robot_description", "/health"))
    signs = orientation_signs()
    last_frame = move.frame(len(move) - 1)
    for joint in decoded["/joint_states"][-1].joints:
        degrees = last_frame[joint.name]
        assert joint.position == pytest.approx(math.radians(signs[joint.name] * degrees), abs=0.02)


@pytest.mark.parametrize("where", ["missing/take.mcap", "there.mcap"])
def test_a_bad_mcap_path_is_one_line_before_the_robot_moves(tmp_path: Path, where: str) -> None:
    (tmp_path / "there.mcap").write_bytes(b"mine")
    done = run_poppy(
        "record",
        "wave",
        "-o",
        str(tmp_path),
        "--mcap",
        str(tmp_path / where),
        "--duration",
        "1",
        "--sim",
        "--profile",
        "ergo-jr",
    )
    assert done.code == 1, done
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in done.stderr, done.stderr
    assert where.split("/")[0] in lines[0]
    assert not (tmp_path / "wave.move").exists()
    assert (tmp_path / "there.mcap").read_bytes() == b"mine"
