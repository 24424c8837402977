"""Host and Origin rules, from a real HTTP client on 127.0.0.1 with forged headers.

What a browser sends is reproduced header by header: a DNS-rebinding page reaches the server
under the attacker's name (``Host``), a page of another site sends ``Origin`` with every POST,
``fetch`` and WebSocket handshake, and ``Sec-Fetch-Site`` with links and images.
"""

from __future__ import annotations

import socket
from collections.abc import Iterator
from urllib.parse import urlsplit

import httpx
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from websockets.exceptions import InvalidStatus
from websockets.sync.client import connect

from poppy_core.server import OriginPolicy
from poppy_core.server.host_names import is_ip, is_loopback, normalize_origin, split_host
from poppy_core.server.origins import Verdict
from tests.helpers.server import Served, serve
from tests.helpers.waiting import http_timeout

EVIL = "https://evil.example"
SNAP = "https://snap.berkeley.edu"


@pytest.fixture(scope="module")
def snap_allowed(moves_folder: str) -> Iterator[Served]:
    """A server allowing Snap!'s origin (``--cors https://snap.berkeley.edu``)."""
    yield from serve(moves_folder, policy=OriginPolicy([SNAP], ["poppy.local"]))


@pytest.fixture(scope="module")
def open_cors(moves_folder: str) -> Iterator[Served]:
    """A server with pypot's open CORS (``--cors '*'``)."""
    yield from serve(moves_folder, policy=OriginPolicy(["*"]))


def _port(served: Served) -> int:
    return int(served.url.rsplit(":", 1)[1])


def _ws(served: Served) -> str:
    return served.url.replace("http://", "ws://") + "/api/v1/ws"


# -- Host: DNS rebinding -----------------------------------------------------------------------


@pytest.mark.parametrize(
    "host",
    ["evil.example", "evil.example:8080", "127.0.0.1.evil.example", "localhost.evil.example"],
)
def test_rebinding_host_names_are_refused(served: Served, host: str) -> None:
    led = served.robot.m2.led
    with httpx.Client(base_url=served.url, headers={"Host": host}, timeout=http_timeout()) as http:
        for method, path, body in [
            ("GET", "/robot.json", None),  # answered by the fast path when allowed
            ("GET", "/motors/m1/registers/present_position/value.json", None),
            ("POST", "/motors/m2/registers/led/value.json", b'"red"'),
            ("GET", "/api/v1/robot", None),
            ("GET", "/docs", None),
        ]:
            answer = http.request(method, path, content=body)
            assert answer.status_code == 400, (path, answer.text)
            error = answer.json()
            assert set(error) >= {"error", "tip", "details"}
            assert "evil.example" in error["error"] and "\n" not in error["error"]
    assert served.robot.m2.led == led
    with (
        pytest.raises(InvalidStatus) as refused,
        connect(_ws(served), additional_headers={"Host": "evil.example"}),
    ):
        pass
    assert refused.value.response.status_code == 400


def test_raw_socket_with_a_forged_host(served: Served) -> None:
    with socket.create_connection(("127.0.0.1", _port(served)), timeout=5) as sock:
        sock.sendall(b"GET /robot.json HTTP/1.1\r\nHost: rebind.attacker.test\r\n\r\n")
        head = sock.recv(4096)
    assert head.startswith(b"HTTP/1.1 400")


@pytest.mark.parametrize(
    "host", ["127.0.0.1", "LOCALHOST", "[::1]", "robot.localhost", "192.168.1.20", "[fe80::1]"]
)
def test_loopback_names_and_addresses_are_answered(served: Served, host: str) -> None:
    with httpx.Client(base_url=served.url, timeout=http_timeout()) as http:
        answer = http.get("/motors/list.json", headers={"Host": f"{host}:{_port(served)}"})
    assert answer.status_code == 200


def test_allowed_host_names(snap_allowed: Served) -> None:
    with httpx.Client(base_url=snap_allowed.url, timeout=http_timeout()) as http:
        assert http.get("/robot.json", headers={"Host": "poppy.local:8080"}).status_code == 200
        assert http.get("/robot.json", headers={"Host": "poppy.example"}).status_code == 400


def test_host_rules_of_a_server_on_every_interface() -> None:
    everywhere = OriginPolicy.for_server("0.0.0.0")
    name = socket.gethostname().split(".")[0].lower()
    assert everywhere.host_allowed(f"{name}.local:8080".encode())
    assert everywhere.host_allowed(b"10.0.0.7:8080")
    assert not everywhere.host_allowed(b"evil.example")
    named = OriginPolicy.for_server("robot.lan", allow_hosts=["Poppy.Local."])
    assert named.host_allowed(b"robot.lan") and named.host_allowed(b"poppy.local")
    assert OriginPolicy(hosts=["*"]).host_allowed(b"anything.example")


# -- Origin: cross-site requests ---------------------------------------------------------------

SIMPLE_POSTS = [  # what a page can send without a preflight (text/plain, forms)
    ("/motors/m3/registers/led/value.json", "text/plain", b'"red"'),
    ("/motors/m3/registers/goal_position/value.json", "text/plain", b"30"),
    (
        "/motors/m3/goto.json",
        "application/x-www-form-urlencoded",
        b'{"position": 30, "duration": 1}',
    ),
    (
        "/motors/goto.json",
        "multipart/form-data; boundary=x",
        b'{"motors": ["m3"], "positions": [30], "duration": 1}',
    ),
    ("/records/stolen/record.json", "text/plain", b""),
    ("/primitives/sinus/properties/amplitude/value.json", "text/plain", b"90"),
    ("/api/v1/gotos", "text/plain", b'{"positions": {"m3": 30}, "duration_s": 1}'),
]


@pytest.mark.parametrize(("path", "content_type", "body"), SIMPLE_POSTS)
def test_simple_cross_site_posts_are_refused(
    served: Served, path: str, content_type: str, body: bytes
) -> None:
    before = (served.robot.m3.led, served.robot.m3.goal_position, served.robot.sinus.amplitude)
    headers = {"Origin": EVIL, "Content-Type": content_type, "Sec-Fetch-Site": "cross-site"}
    with httpx.Client(base_url=served.url, timeout=http_timeout()) as http:
        answer = http.post(path, content=body, headers=headers)
        assert answer.status_code == 403, answer.text
        assert "access-control-allow-origin" not in answer.headers
        assert f"--cors {EVIL}" in answer.json()["error"]
        assert http.get("/api/v1/moves/status").json()["recording"] == []
    after = (served.robot.m3.led, served.robot.m3.goal_position, served.robot.sinus.amplitude)
    assert after == before


def test_cross_site_reads_and_preflights_are_refused(served: Served) -> None:
    with httpx.Client(base_url=served.url, timeout=http_timeout()) as http:
        read = http.get("/robot.json", headers={"Origin": EVIL})
        assert read.status_code == 403 and "access-control-allow-origin" not in read.headers
        preflight = http.options(
            "/api/v1/motors/m1/registers/led",
            headers={"Origin": EVIL, "Access-Control-Request-Method": "PUT"},
        )
        assert preflight.status_code == 403
        assert "access-control-allow-origin" not in preflight.headers
        for origin in ("null", "http://localhost.evil.example", "not an origin"):
            assert http.get("/robot.json", headers={"Origin": origin}).status_code == 403


def test_links_and_images_cannot_start_a_primitive(served: Served) -> None:
    # <img src=".../primitives/sinus/start.json">: a GET without Origin, Sec-Fetch-Site cross-site
    with httpx.Client(base_url=served.url, timeout=http_timeout()) as http:
        spellings = (  # every spelling reaching the route (chromium tries them: test_browser)
            "/primitives/sinus/start.json",
            "/primitive/sinus/start.json",
            "/primitives/sinus/start.json/",
            "/primitive%2Fsinus/start.json",
        )
        for site in ("cross-site", "same-site"):
            for path in spellings:
                answer = http.get(path, headers={"Sec-Fetch-Site": site})
                assert answer.status_code == 403, path
        assert not served.robot.sinus.is_alive()
        # a link to a page that only reads still opens
        docs = http.get("/docs", headers={"Sec-Fetch-Site": "cross-site"})
        assert docs.status_code == 200
        # the user typing the URL (Sec-Fetch-Site: none) or a script (no header) still works
        started = http.get("/primitives/sinus/start.json", headers={"Sec-Fetch-Site": "none"})
        assert started.status_code == 202
        assert http.get("/primitives/sinus/stop.json").status_code == 202


def test_the_servers_own_pages_are_answered(served: Served) -> None:
    port = _port(served)
    with httpx.Client(base_url=served.url, timeout=http_timeout()) as http:
        for origin in (f"http://127.0.0.1:{port}", f"http://localhost:{port}"):
            headers = {"Origin": origin, "Content-Type": "application/json"}
            answer = http.post(
                "/motors/m4/registers/led/value.json", content=b'"blue"', headers=headers
            )
            assert answer.status_code == 202, answer.text
        # same origin under another (allowed) name: the Swagger page opened at [::1]
        answer = http.get(
            "/api/v1/robot", headers={"Host": f"[::1]:{port}", "Origin": f"http://[::1]:{port}"}
        )
        assert answer.status_code == 200
        # the same host on another port is not this server's page
        other = http.get("/robot.json", headers={"Origin": f"http://127.0.0.1:{port + 1}"})
        assert other.status_code == 403
    served.robot.m4.led = "off"


def test_an_allowed_origin_gets_cors(snap_allowed: Served) -> None:
    with httpx.Client(base_url=snap_allowed.url, timeout=http_timeout()) as http:
        read = http.get(
            "/motors/m1/registers/present_position/value.json", headers={"Origin": SNAP}
        )
        assert read.status_code == 200
        assert read.headers["access-control-allow-origin"] == SNAP
        assert read.headers["vary"] == "Origin"
        write = http.post(
            "/motors/m5/registers/led/value.json",
            content=b'"green"',
            headers={"Origin": SNAP, "Content-Type": "text/plain"},
        )
        assert write.status_code == 202 and snap_allowed.robot.m5.led == "green"
        preflight = http.options(
            "/api/v1/motors/m5/registers/led",
            headers={
                "Origin": SNAP,
                "Access-Control-Request-Method": "PUT",
                "Access-Control-Request-Private-Network": "true",
            },
        )
        assert preflight.status_code == 204
        assert preflight.headers["access-control-allow-origin"] == SNAP
        assert "PUT" in preflight.headers["access-control-allow-methods"]
        assert preflight.headers["access-control-allow-private-network"] == "true"
        assert http.get("/robot.json", headers={"Origin": EVIL}).status_code == 403
    snap_allowed.robot.m5.led = "off"


def test_open_cors_is_pypots_but_keeps_the_host_check(open_cors: Served) -> None:
    with httpx.Client(base_url=open_cors.url, timeout=http_timeout()) as http:
        answer = http.post(
            "/motors/m6/registers/led/value.json",
            content=b'"pink"',
            headers={"Origin": EVIL, "Content-Type": "text/plain"},
        )
        assert answer.status_code == 202
        assert answer.headers["access-control-allow-origin"] == "*"
        plain = http.get("/robot.json")  # pypot's headers on every answer
        assert plain.headers["access-control-allow-origin"] == "*"
        assert "POST" in plain.headers["access-control-allow-methods"]
        assert "Content-Type" in plain.headers["access-control-allow-headers"]
        options = http.options("/motors/m1/registers/goal_position/value.json")
        assert options.status_code == 204 and options.headers["access-control-allow-origin"] == "*"
        assert http.get("/robot.json", headers={"Host": "evil.example"}).status_code == 400
    with connect(_ws(open_cors), origin=EVIL) as ws:
        assert "m1" in ws.recv(timeout=5)
    open_cors.robot.m6.led = "off"


# -- WebSocket ---------------------------------------------------------------------------------


def test_websocket_handshakes_follow_the_origin_rules(served: Served, snap_allowed: Served) -> None:
    with pytest.raises(InvalidStatus) as refused, connect(_ws(served), origin=EVIL):
        pass
    assert refused.value.response.status_code == 403
    assert b"--cors" in refused.value.response.body
    own = f"http://127.0.0.1:{_port(served)}"
    for origin in (None, own):
        with connect(_ws(served), origin=origin) as ws:
            assert "m1" in ws.recv(timeout=5)
    with connect(_ws(snap_allowed), origin=SNAP) as ws:
        assert "m1" in ws.recv(timeout=5)
    with pytest.raises(InvalidStatus), connect(_ws(snap_allowed), origin=EVIL):
        pass


# -- the policy itself -------------------------------------------------------------------------


def test_a_refused_origin_is_reported_once_with_the_option_to_allow_it(moves_folder: str) -> None:
    lines: list[str] = []
    policy = OriginPolicy(report=lines.append)
    for served in serve(moves_folder, policy=policy):
        with httpx.Client(base_url=served.url, timeout=http_timeout()) as http:
            for _ in range(3):
                http.get("/robot.json", headers={"Origin": "https://Snap.Berkeley.edu:443"})
            http.get("/robot.json", headers={"Host": "evil.example"})
    assert len(lines) == 2
    assert lines[0].endswith("restart poppy serve with --cors https://snap.berkeley.edu")
    assert "--allow-host evil.example" in lines[1]


@pytest.mark.parametrize(
    ("text", "normal"),
    [
        ("HTTPS://Snap.Berkeley.edu:443/", "https://snap.berkeley.edu"),
        ("http://localhost:8000", "http://localhost:8000"),
        ("http://[::1]:80", "http://[::1]"),
        ("*", "*"),
        ("null", "null"),
    ],
)
def test_origins_are_normalized(text: str, normal: str) -> None:
    assert normalize_origin(text) == normal


@pytest.mark.parametrize(
    "text", ["snap.berkeley.edu", "ftp://x.example", "https://x.example/path", "https://x:99999"]
)
def test_what_is_not_an_origin_is_refused(text: str) -> None:
    with pytest.raises(ValueError, match=r"not an origin|out of range"):
        OriginPolicy([text])


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=80), st.one_of(st.none(), st.integers(0, 65535)))
def test_any_host_header_gets_an_answer_not_an_exception(host: bytes, port: int | None) -> None:
    policy = OriginPolicy()
    allowed = policy.host_allowed(host)
    name, _ = split_host(host.decode("latin-1"))
    if allowed:
        assert name in ("localhost", "127.0.0.1", "::1") or is_loopback(name) or is_ip(name)


@settings(max_examples=300, deadline=None)
@given(st.text(max_size=80), st.sampled_from([b"127.0.0.1:8080", b"localhost", None]))
def test_any_origin_header_gets_a_verdict_and_foreign_text_is_refused(
    origin: str, host: bytes | None
) -> None:
    policy = OriginPolicy()
    verdict = policy.verdict(origin.encode("utf-8"), host, 8080)
    assert verdict is not Verdict.ALLOWED  # nothing is allowed unless listed
    if verdict is Verdict.OWN:
        parts = urlsplit(normalize_origin(origin.encode("utf-8").decode("latin-1")))
        assert is_loopback(parts.hostname or "") and (parts.port or 80) == 8080
