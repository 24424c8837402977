"""A fake Snap! release (a zip of snap.html and a small script) served from loopback HTTP.

The fake's script opens the ``#open:`` URL it is given (the Poppy blocks, as Snap! would),
then calls the Snap! route written in the blocks' first ``reportURL`` of ``set/registers``
with a goal it names in the page: enough for a browser test to see the blocks loaded and the
robot moved without a real Snap!.
"""

from __future__ import annotations

import http.server
import io
import threading
import zipfile
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

from poppy_core.server.snap.release import release_digest

SNAP_HTML = """<!doctype html>
<html><head><meta charset="utf-8"><title>a fake Snap!</title>
<script src="src/fake-snap.js"></script></head>
<body><p id="state">loading</p></body></html>
"""
# reads #open:URL, fetches the blocks (same origin), then moves m1 through the Snap! routes
FAKE_SNAP_JS = """
window.addEventListener("load", async () => {
  const state = document.getElementById("state");
  const hash = decodeURIComponent(location.hash);
  if (!hash.startsWith("#open:")) { state.textContent = "no #open:"; return; }
  const blocks = await (await fetch(hash.slice(6))).text();
  const loaded = blocks.includes("<blocks") ? "blocks loaded" : "no blocks";
  const base = new URL(hash.slice(6)).origin;
  await fetch(`${base}/motors/set/registers/m1:compliant:False;m1:goal_position:25`);
  state.textContent = loaded;
  document.title = loaded;
});
"""


@dataclass
class FakeRelease:
    """A release's files (under ``Snap-<version>/`` in the zip), its zip and its digest."""

    version: str
    folder: Path
    data: bytes = b""
    digest: str = ""


def make_release(
    where: Path, version: str = "0.0-test", extra: dict[str, str] | None = None
) -> FakeRelease:
    """Write a fake release's folder under ``where`` and zip it as GitHub does (one top folder)."""
    folder = where / f"Snap-{version}"
    (folder / "src").mkdir(parents=True)
    (folder / "snap.html").write_text(SNAP_HTML, encoding="utf-8")
    (folder / "src" / "fake-snap.js").write_text(FAKE_SNAP_JS, encoding="utf-8")
    for name, text in (extra or {}).items():
        (folder / name).write_text(text, encoding="utf-8")
    return FakeRelease(version, folder, zip_folder(folder), release_digest(folder))


def zip_folder(folder: Path, top: str | None = None) -> bytes:
    """The zip of ``folder``'s files under ``top/`` (its own name by default)."""
    buffer = io.BytesIO()
    prefix = top if top is not None else folder.name
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as zipped:
        for path in sorted(folder.rglob("*")):
            if path.is_file():
                zipped.write(path, f"{prefix}/{path.relative_to(folder).as_posix()}")
    return buffer.getvalue()


@dataclass
class Files:
    """What the loopback server serves: path -> bytes; ``cut`` paths stop halfway."""

    bodies: dict[str, bytes] = field(default_factory=dict)
    cut: set[str] = field(default_factory=set)
    requests: list[str] = field(default_factory=list)


@contextmanager
def release_server(files: Files) -> Iterator[str]:
    """An HTTP server on 127.0.0.1 serving ``files``; yields its base URL."""

    class Handler(http.server.BaseHTTPRequestHandler):
        def do_GET(self) -> None:
            files.requests.append(self.path)
            body = files.bodies.get(self.path)
            if body is None:
                self.send_error(404)
                return
            self.send_response(200)
            self.send_header("Content-Type", "application/zip")
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body[: len(body) // 2] if self.path in files.cut else body)

        def log_message(self, format: str, *args: object) -> None:
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()
        thread.join(timeout=10)
