"""The datasets' routes of the page (/api/v1/datasets) over a real served robot: the data
folder's datasets and one added by name, an episode's frames, the video file with HTTP Range
(the browser seeks in it), the token and Host rules, and bad inputs refused in one line."""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest

pytest.importorskip("pyarrow")
pytest.importorskip("av")

from poppy_core import from_profile
from poppy_core.server.web.datasets import add_dataset
from tests.helpers.datasets import EPISODES, FPS, MOTORS, action, state, write_dataset
from tests.helpers.server import Served, serve_robot
from tests.helpers.waiting import http_timeout

TOKEN = "dataset-token"


@pytest.fixture(scope="module")
def home(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """LeRobot's home with me/wave, and a dataset elsewhere (added by name)."""
    folder = tmp_path_factory.mktemp("lerobot")
    write_dataset(folder / "me" / "wave")
    write_dataset(folder.parent / "elsewhere" / "extra", robot_type=None)
    (folder / "me" / "notes").mkdir()  # a folder without meta/info.json: not a dataset
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("HF_LEROBOT_HOME", str(folder))
        yield folder


@pytest.fixture(scope="module")
def served(home: Path) -> Iterator[Served]:
    for served in serve_robot(from_profile("ergo-jr", sim=True)):
        add_dataset(served.app, "class/extra", home.parent / "elsewhere" / "extra")
        yield served


@pytest.fixture
def client(served: Served) -> Iterator[httpx.Client]:
    with httpx.Client(base_url=served.url, timeout=http_timeout(10.0)) as client:
        yield client


def test_the_datasets_are_listed_with_their_episodes(client: httpx.Client, home: Path) -> None:
    answer = client.get("/api/v1/datasets").json()
    assert answer["home"] == str(home)
    found = {d["repo_id"]: d for d in answer["datasets"]}
    assert list(found) == ["class/extra", "me/wave"]
    wave = found["me/wave"]
    assert wave["fps"] == FPS and wave["cameras"] == ["top"] and wave["robot_type"] == "ergo-jr"
    assert wave["joints"] == [f"{m}.pos" for m in MOTORS]
    assert [(e["index"], e["frames"], e["tasks"]) for e in wave["episodes"]] == [
        (0, 3, ["stay"]),
        (1, 30, ["wave"]),
    ]
    assert wave["episodes"][1]["duration_s"] == pytest.approx(3.0)
    assert found["class/extra"]["root"] == str(home.parent / "elsewhere" / "extra")


def test_an_episode_gives_its_frames_and_its_span_in_the_packed_video(
    client: httpx.Client,
) -> None:
    episode = client.get("/api/v1/datasets/me/wave/episodes/1").json()
    frames = EPISODES[1][0]
    assert episode["repo_id"] == "me/wave" and episode["episode"] == 1
    assert episode["motors"] == list(MOTORS) and episode["tasks"] == ["wave"]
    assert episode["frames"] == frames and episode["fps"] == FPS
    assert episode["timestamps"] == pytest.approx([k / FPS for k in range(frames)])
    for k in (0, 7, frames - 1):
        assert episode["state"][k] == pytest.approx(state(k), abs=1e-3)
        assert episode["action"][k] == pytest.approx(action(k), abs=1e-3)
    (video,) = episode["videos"]
    before = EPISODES[0][0] / FPS  # episode 0's frames come first in the file
    assert video["camera"] == "top"
    assert video["from_s"] == pytest.approx(before)
    assert video["to_s"] == pytest.approx(before + frames / FPS)
    assert video["url"] == "/api/v1/datasets/me/wave/episodes/1/video/top"


def test_the_video_is_served_whole_and_by_ranges(client: httpx.Client, home: Path) -> None:
    path = home / "me/wave/videos/observation.images.top/chunk-000/file-000.mp4"
    size = path.stat().st_size
    whole = client.get("/api/v1/datasets/me/wave/episodes/1/video/top")
    assert whole.status_code == 200 and whole.headers["content-type"] == "video/mp4"
    assert whole.content == path.read_bytes()
    assert whole.headers.get("accept-ranges") == "bytes"
    part = client.get(
        "/api/v1/datasets/me/wave/episodes/1/video/top", headers={"Range": "bytes=100-199"}
    )
    assert part.status_code == 206, part.text
    assert part.headers["content-range"] == f"bytes 100-199/{size}"
    assert part.content == path.read_bytes()[100:200]
    tail = client.get(
        "/api/v1/datasets/me/wave/episodes/0/video/top", headers={"Range": f"bytes={size - 10}-"}
    )
    assert tail.status_code == 206 and tail.content == path.read_bytes()[-10:]


@pytest.mark.parametrize(
    ("path", "status", "words"),
    [
        ("/api/v1/datasets/me/nothing/episodes/0", 404, "no dataset 'me/nothing'"),
        ("/api/v1/datasets/me/notes/episodes/0", 404, "no dataset 'me/notes'"),
        ("/api/v1/datasets/me/wave/episodes/5", 404, "no episode 5"),
        ("/api/v1/datasets/me/wave/episodes/-1", 422, ""),
        ("/api/v1/datasets/me/wave/episodes/x", 422, ""),
        ("/api/v1/datasets/me/wave/episodes/1/video/side", 404, "no camera 'side'"),
        ("/api/v1/datasets/me/wave/episodes/9/video/top", 404, "no episode 9"),
        ("/api/v1/datasets/%2E%2E/wave/episodes/0", 422, "is not a dataset name"),
        ("/api/v1/datasets/me/%2E%2E/episodes/0", 422, "is not a dataset name"),
    ],
)
def test_bad_requests_are_refused_in_one_line(
    client: httpx.Client, path: str, status: int, words: str
) -> None:
    answer = client.get(path)
    assert answer.status_code == status, answer.text
    detail = answer.json()["detail"]
    if words:
        assert isinstance(detail, str) and "\n" not in detail and words in detail, detail


def test_a_video_linked_out_of_the_dataset_is_refused(
    tmp_path: Path, served: Served, client: httpx.Client
) -> None:
    root = tmp_path / "linked"
    write_dataset(root)
    video = root / "videos/observation.images.top/chunk-000/file-000.mp4"
    outside = tmp_path / "outside.mp4"
    video.replace(outside)
    os.symlink(outside, video)
    add_dataset(served.app, "me/linked", root)
    try:
        answer = client.get("/api/v1/datasets/me/linked/episodes/1/video/top")
        assert answer.status_code == 422, answer.text
        assert "outside the dataset's folder" in answer.json()["detail"]
        assert client.get("/api/v1/datasets/me/linked/episodes/1").status_code == 422
    finally:
        served.app.state.datasets_extra.pop("me/linked")


def test_a_foreign_host_is_refused(client: httpx.Client) -> None:
    answer = client.get("/api/v1/datasets", headers={"Host": "evil.example"})
    assert answer.status_code in (400, 403, 421), answer.text


def test_with_a_token_the_routes_need_it(home: Path) -> None:
    for served in serve_robot(from_profile("ergo-jr", sim=True), token=TOKEN):
        with httpx.Client(base_url=served.url, timeout=http_timeout(10.0)) as client:
            video = "/api/v1/datasets/me/wave/episodes/1/video/top"
            for path in ("/api/v1/datasets", "/api/v1/datasets/me/wave/episodes/1", video):
                assert client.get(path).status_code == 401, path
            bearer = {"Authorization": f"Bearer {TOKEN}"}
            assert client.get("/api/v1/datasets", headers=bearer).status_code == 200
            assert client.get(video, headers={**bearer, "Range": "bytes=0-9"}).status_code == 206
