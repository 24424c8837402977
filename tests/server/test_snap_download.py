"""`poppy snap download`: a Snap! release fetched from a (loopback) server, checked against its
digest, unpacked atomically into the user data folder, then served by `poppy serve --snap`."""

from __future__ import annotations

import io
import json
import os
import signal
import stat
import subprocess
import tarfile
import urllib.request
import zipfile
from pathlib import Path

import pytest

from poppy_core.errors import ArgumentError, DownloadError
from poppy_core.server.snap import release, unpack
from tests.helpers.cli import POPPY, command_env, run_poppy
from tests.helpers.processes import reap
from tests.helpers.snap_release import Files, make_release, release_server, zip_folder

TIMEOUT_S = 90


@pytest.fixture
def data_home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A user data folder of the test's own (platformdirs reads XDG_DATA_HOME)."""
    home = tmp_path / "data"
    monkeypatch.setenv("XDG_DATA_HOME", str(home))
    return home


def _leftovers() -> list[str]:
    folder = release.releases_folder()
    return sorted(p.name for p in folder.iterdir()) if folder.is_dir() else []


def test_a_release_is_downloaded_checked_and_installed_once(
    tmp_path: Path, data_home: Path
) -> None:
    fake = make_release(tmp_path / "src")
    files = Files({"/snap.zip": fake.data})
    with release_server(files) as base:
        copy = release.download(fake.version, f"{base}/snap.zip", fake.digest)
        again = release.download(fake.version, f"{base}/snap.zip", fake.digest)
    assert copy.downloaded and not again.downloaded
    assert files.requests == ["/snap.zip"]  # once: the second call found the copy
    assert copy.path == data_home / "poppy" / "snap" / fake.version
    assert (copy.path / "snap.html").read_text() == (fake.folder / "snap.html").read_text()
    assert (copy.path / "src" / "fake-snap.js").is_file()
    assert release.release_digest(copy.path) == fake.digest
    assert release.installed() == again
    assert _leftovers() == [fake.version]
    marker = json.loads((copy.path / release.MARKER).read_text())
    assert marker["digest"] == fake.digest and marker["source"] == f"{base}/snap.zip"


def test_a_release_that_does_not_match_its_digest_is_refused_and_nothing_is_left(
    tmp_path: Path, data_home: Path
) -> None:
    fake = make_release(tmp_path / "src")
    other = make_release(tmp_path / "other", extra={"evil.js": "alert(1)"})
    files = Files({"/snap.zip": other.data})
    with release_server(files) as base, pytest.raises(DownloadError, match="does not match"):
        release.download(fake.version, f"{base}/snap.zip", fake.digest)
    assert release.installed() is None
    assert _leftovers() == []


def test_a_download_cut_short_leaves_no_half_folder(tmp_path: Path, data_home: Path) -> None:
    fake = make_release(tmp_path / "src")
    files = Files({"/snap.zip": fake.data}, cut={"/snap.zip"})
    with release_server(files) as base, pytest.raises(DownloadError, match="broke off"):
        release.download(fake.version, f"{base}/snap.zip", fake.digest)
    assert _leftovers() == []


def test_force_replaces_an_installed_copy_only_with_a_checked_one(
    tmp_path: Path, data_home: Path
) -> None:
    first = make_release(tmp_path / "a")
    second = make_release(tmp_path / "b", extra={"new.txt": "two"})
    files = Files({"/a.zip": first.data, "/b.zip": second.data})
    with release_server(files) as base:
        release.download(first.version, f"{base}/a.zip", first.digest)
        with pytest.raises(DownloadError):  # the wrong digest: the old copy stays whole
            release.download(first.version, f"{base}/b.zip", first.digest, force=True)
        assert release.release_digest(release.releases_folder() / first.version) == first.digest
        copy = release.download(first.version, f"{base}/b.zip", second.digest, force=True)
    assert (copy.path / "new.txt").read_text() == "two"
    assert _leftovers() == [first.version]


def test_archives_reaching_outside_their_folder_or_without_snap_html_are_refused(
    tmp_path: Path, data_home: Path
) -> None:
    fake = make_release(tmp_path / "src")
    (tmp_path / "empty" / "x").mkdir(parents=True)
    (tmp_path / "empty" / "x" / "index.html").write_text("not Snap!")
    linked = io.BytesIO()
    with zipfile.ZipFile(linked, "w") as zipped:
        zipped.writestr("Snap/snap.html", "<html></html>")
        link = zipfile.ZipInfo("Snap/passwd")
        link.external_attr = (stat.S_IFLNK | 0o777) << 16
        zipped.writestr(link, "/etc/passwd")
    files = Files(
        {
            "/up.zip": zip_folder(fake.folder, top=".."),
            "/none.zip": zip_folder(tmp_path / "empty"),
            "/link.zip": linked.getvalue(),
        }
    )
    with release_server(files) as base:
        with pytest.raises(DownloadError, match="holds a link"):
            release.download("link", f"{base}/link.zip", fake.digest)
        with pytest.raises(DownloadError, match="outside its folder"):
            release.download("up", f"{base}/up.zip", fake.digest)
        with pytest.raises(DownloadError, match=r"no snap\.html"):
            release.download("none", f"{base}/none.zip", fake.digest)
        with pytest.raises(DownloadError, match="404"):
            release.download("gone", f"{base}/gone.zip", fake.digest)
    assert _leftovers() == []


def test_the_pinned_release_is_github_s_tag_archive() -> None:
    plan = release.plan()
    assert plan.version == release.PINNED.version
    assert plan.url == f"https://github.com/jmoenig/Snap/archive/refs/tags/v{plan.version}.zip"
    assert len(plan.digest) == 64
    with pytest.raises(ArgumentError, match="no pinned digest"):
        release.plan("9.9.9", "http://127.0.0.1:1/x.zip")
    with pytest.raises(ArgumentError, match="not a SHA-256"):
        release.plan(None, None, "abc")
    with pytest.raises(ArgumentError, match="not a Snap! version"):
        release.plan("../etc")


def test_the_command_downloads_and_says_so(tmp_path: Path) -> None:
    fake = make_release(tmp_path / "src")
    env = {"XDG_DATA_HOME": str(tmp_path / "data")}
    with release_server(Files({"/snap.zip": fake.data})) as base:
        args = ["snap", "download", fake.version, "--from", f"{base}/snap.zip"]
        done = run_poppy(*args, "--sha256", fake.digest, "--json", env=env)
        assert done.code == 0, done.stderr
        assert done.json()["downloaded"] is True and done.json()["digest"] == fake.digest
        again = run_poppy(*args, "--sha256", fake.digest, env=env)
        assert again.code == 0 and "already installed" in again.stdout
        for bad, says in [
            (["--sha256", "xyz"], "is not a SHA-256"),
            (["--sha256", "0" * 64, "--force"], "does not match the pinned digest"),
        ]:
            refused = run_poppy(*args, *bad, env=env)
            assert refused.code != 0 and says in refused.stderr
            assert "Traceback" not in refused.stderr and len(refused.stderr.splitlines()) <= 2
    for bad, says in [
        (["snap", "download", "1.2.3"], "no pinned digest for Snap! 1.2.3"),
        (["snap", "download", "--from", "ftp://x/y.zip"], "give an http(s) URL"),
        (["snap", "download", "--from", str(tmp_path / "none.zip")], "cannot read"),
    ]:
        refused = run_poppy(*bad, env=env)
        assert refused.code != 0 and says in refused.stderr, refused.stderr
        assert "Traceback" not in refused.stderr


def _serve_snap(env: dict[str, str]) -> tuple[subprocess.Popen[str], dict[str, str]]:
    args = ["serve", "--http", "--http-port", "0", "--snap", "--snap-port", "0"]
    proc = subprocess.Popen(
        [*POPPY, *args, "--sim", "--profile", "ergo-jr"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=dict(os.environ, **command_env(), **env),
    )
    assert proc.stdout is not None
    lines = [proc.stdout.readline().strip() for _ in range(4)]
    found = {"http": lines[0]}
    for line in lines:
        if line.startswith("snap: "):
            found["snap"] = line.split()[1]
        if line.startswith("Snap! with the Poppy blocks: "):
            found["editor"] = line.split(": ", 1)[1]
    return proc, found


def _get(url: str) -> str:
    with urllib.request.urlopen(url, timeout=20) as answer:
        return str(answer.read().decode())


def test_serve_snap_serves_the_downloaded_copy_and_says_how_to_get_one(tmp_path: Path) -> None:
    env = {"XDG_DATA_HOME": str(tmp_path / "data"), "POPPY_MOVES_DIR": str(tmp_path / "m")}
    proc, urls = _serve_snap(env)
    try:  # no download yet: Snap! online, and the page says how to get it offline
        assert urls["editor"].startswith("https://snap.berkeley.edu/snap/snap.html#open:")
        notes = json.loads(_get(f"{urls['http']}/api/v1/web/about"))["notes"]
        assert "poppy snap download" in notes["snap"]
    finally:
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=TIMEOUT_S)
    assert "poppy snap download" in err and "Traceback" not in err
    fake = make_release(tmp_path / "src")
    with release_server(Files({"/snap.zip": fake.data})) as base:
        args = ["snap", "download", fake.version, "--from", f"{base}/snap.zip"]
        assert run_poppy(*args, "--sha256", fake.digest, env=env).code == 0
    proc, urls = _serve_snap(env)
    try:
        snap = urls["snap"]
        assert urls["editor"] == f"{snap}/app/snap.html#open:{snap}/snap-blocks.xml"
        assert "a fake Snap!" in _get(f"{snap}/app/snap.html")
        about = json.loads(_get(f"{urls['http']}/api/v1/web/about"))
        assert about["links"]["Snap! with the Poppy blocks"] == urls["editor"]
        assert about["notes"] == {}
    finally:
        reap(proc)


def test_a_tar_gz_release_is_taken_too(tmp_path: Path, data_home: Path) -> None:
    import tarfile

    fake = make_release(tmp_path / "src")
    archive = tmp_path / "snap.tar.gz"
    with tarfile.open(archive, "w:gz") as tarred:
        tarred.add(fake.folder, arcname=fake.folder.name)
    copy = release.download(fake.version, archive.as_uri(), fake.digest)
    assert release.release_digest(copy.path) == fake.digest


@pytest.mark.parametrize("kind", ["zip", "tar"])
def test_an_archive_of_too_many_entries_is_refused_folders_counted(
    tmp_path: Path, data_home: Path, monkeypatch: pytest.MonkeyPatch, kind: str
) -> None:
    # 60,000 empty folders are no Snap! release: every entry counts, before it is made
    monkeypatch.setattr(unpack, "MAX_FILES", 100)
    made: list[str] = []
    real_mkdir = Path.mkdir

    def mkdir(self: Path, *args: object, **kwargs: object) -> None:
        made.append(self.name)
        real_mkdir(self, *args, **kwargs)  # type: ignore[arg-type]

    archive = tmp_path / f"folders.{kind}"
    if kind == "zip":
        with zipfile.ZipFile(archive, "w") as zipped:
            zipped.writestr("Snap/snap.html", "<html></html>")
            for number in range(300):
                zipped.writestr(f"Snap/empty-{number}/", "")
    else:
        with tarfile.open(archive, "w") as tarred:
            for number in range(300):
                folder = tarfile.TarInfo(f"Snap/empty-{number}")
                folder.type = tarfile.DIRTYPE
                tarred.addfile(folder)
    monkeypatch.setattr(Path, "mkdir", mkdir)
    with pytest.raises(DownloadError, match="more than a Snap! release"):
        release.download("folders", str(archive), "0" * 64)
    assert len({m for m in made if m.startswith("empty-")}) <= 100
    assert _leftovers() == []


@pytest.mark.parametrize("claimed", [0, 3])
def test_a_zip_member_with_a_false_size_is_refused_in_one_line(
    tmp_path: Path, data_home: Path, claimed: int
) -> None:
    archive = tmp_path / "lying.zip"
    with zipfile.ZipFile(archive, "w") as zipped:
        zipped.writestr("Snap/snap.html", "<html>" + "x" * 500 + "</html>")
        zipped.infolist()[0].file_size = claimed  # the central directory lies
    with pytest.raises(DownloadError) as caught:
        release.download("lying", str(archive), "0" * 64)
    assert "damaged" in str(caught.value) and "\n" not in str(caught.value)
    assert _leftovers() == []
