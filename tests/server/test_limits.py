"""Connection limits: a deadline for request headers, a cap on open connections (503), bounded fds.

Raw sockets on 127.0.0.1 play the slow and idle clients; no assertion is about speed: every
wait has a generous bound and only says that the server ends what it must end.
"""

from __future__ import annotations

import os
import socket
import time
from collections.abc import Iterator

import httpx
import pytest
from websockets.sync.client import connect

from poppy_core import from_profile
from poppy_core.server import ServerThread, create_app, limits
from tests.helpers.waiting import eventually, scaled

WAIT_S = 15.0  # upper bound for what should take well under a second


@pytest.fixture(scope="module")
def strict(moves_folder: str) -> Iterator[ServerThread]:
    """A served Ergo Jr with a 0.5 s header deadline and at most 20 connections."""
    robot = from_profile("ergo-jr", sim=True)
    server = ServerThread(create_app(robot), header_timeout_s=0.5, max_connections=20).start()
    yield server
    server.stop()
    robot.close()


@pytest.fixture
def capped(moves_folder: str) -> Iterator[ServerThread]:
    """A served Ergo Jr with at most 20 connections, whose idle ones stay open while a test runs:
    its header deadline (30 s times the load factor) outlives the test even on a busy machine,
    where a 0.5 s one closed idle sockets before the connection beyond the cap came."""
    robot = from_profile("ergo-jr", sim=True)
    server = ServerThread(
        create_app(robot), header_timeout_s=scaled(30.0), max_connections=20
    ).start()
    yield server
    server.stop()
    robot.close()


def _closed_within(sock: socket.socket, seconds: float) -> bytes:
    """Everything the server sends until it closes ``sock`` (fails if it does not)."""
    sock.settimeout(seconds)
    received = b""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        chunk = sock.recv(4096)
        if not chunk:
            return received
        received += chunk
    raise AssertionError("the server kept the connection open")


def test_slow_headers_are_cut(strict: ServerThread) -> None:
    with socket.create_connection(("127.0.0.1", strict.port)) as sock:
        sock.sendall(b"GET /robot.json HTTP/1.1\r\nHost: 127.0.0.1\r\n")  # never ends
        answer = _closed_within(sock, scaled(WAIT_S))
    assert answer.startswith(b"HTTP/1.1 408")
    assert b'"error": "the request\'s headers did not arrive within 0.5 s"' in answer


def test_idle_connections_are_closed(strict: ServerThread) -> None:
    with socket.create_connection(("127.0.0.1", strict.port)) as sock:
        assert _closed_within(sock, scaled(WAIT_S)) == b""


def test_slow_headers_after_a_keep_alive_answer_are_cut(strict: ServerThread) -> None:
    with socket.create_connection(("127.0.0.1", strict.port)) as sock:
        sock.sendall(b"GET /motors/list.json HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
        sock.settimeout(scaled(WAIT_S))
        assert sock.recv(4096).startswith(b"HTTP/1.1 200")
        sock.sendall(b"GET /motors/list.json HTTP/1.1\r\n")
        for _ in range(3):  # a byte now and then does not keep it open
            time.sleep(0.2)
            sock.sendall(b"X")
        assert b"408" in _closed_within(sock, scaled(WAIT_S))


def test_long_requests_and_websockets_outlive_the_header_deadline(strict: ServerThread) -> None:
    with httpx.Client(base_url=strict.url, timeout=scaled(WAIT_S)) as http:
        http.put("/api/v1/robot/compliant", json={"compliant": False})
        body = {"positions": {"m1": 5}, "duration_s": 1.2, "wait": True}
        answer = http.post("/api/v1/gotos", json=body)  # answers after 1.2 s > 0.5 s
        assert answer.status_code == 200 and answer.json()["waited"] is True
        http.put("/api/v1/robot/compliant", json={"compliant": True})
    with connect(strict.url.replace("http://", "ws://") + "/api/v1/ws?rate_hz=10") as ws:
        end = time.monotonic() + 1.5
        while time.monotonic() < end:
            assert "m1" in ws.recv(timeout=scaled(5.0))


def test_a_connection_beyond_the_cap_gets_a_clear_503(capped: ServerThread) -> None:
    with httpx.Client(base_url=capped.url, timeout=scaled(WAIT_S)) as http:
        assert http.get("/motors/list.json").status_code == 200  # the client's own connection
        # accepted in the order they were made (the listen queue), so before the 21st below
        idle = [socket.create_connection(("127.0.0.1", capped.port)) for _ in range(19)]
        try:
            with httpx.Client(base_url=capped.url, timeout=scaled(WAIT_S)) as other:
                refused = other.get("/motors/list.json")
            assert refused.status_code == 503
            assert refused.json()["error"] == "too many connections: this server accepts 20 at once"
            assert http.get("/motors/list.json").status_code == 200  # open ones go on
        finally:
            for sock in idle:
                sock.close()

    def a_slot_came_back() -> bool:  # once the idle sockets are gone
        with httpx.Client(base_url=capped.url, timeout=scaled(WAIT_S)) as other:
            return other.get("/motors/list.json").status_code == 200

    assert eventually(a_slot_came_back, timeout_s=WAIT_S, interval_s=0.1)


def _open_fds() -> int:
    return len(os.listdir("/proc/self/fd"))


@pytest.mark.skipif(not os.path.isdir("/proc/self/fd"), reason="needs /proc (Linux)")
def test_a_flood_of_idle_sockets_does_not_exhaust_file_descriptors(moves_folder: str) -> None:
    robot = from_profile("ergo-jr", sim=True)
    server = ServerThread(create_app(robot), max_connections=50).start()
    try:
        before = _open_fds()
        flood = [socket.create_connection(("127.0.0.1", server.port)) for _ in range(400)]
        time.sleep(2.0)  # accepted, refused ones answered and closed after their linger
        held_by_server = _open_fds() - before - len(flood)
        assert held_by_server <= 60, held_by_server
        with httpx.Client(base_url=server.url, timeout=scaled(WAIT_S)) as http:
            assert http.get("/motors/list.json").status_code == 503
        for sock in flood:
            sock.close()
    finally:
        server.stop()
        robot.close()


def _refused_head(port: int, head: bytes) -> bytes:
    """Send ``head`` (in pieces, stopping when the server closes) and read the answer."""
    with socket.create_connection(("127.0.0.1", port)) as sock:
        try:
            for start in range(0, len(head), 16384):
                sock.sendall(head[start : start + 16384])
        except (BrokenPipeError, ConnectionResetError):
            pass  # closed once the limit was passed: the answer is already on its way
        try:
            return _closed_within(sock, scaled(WAIT_S))
        except ConnectionResetError:
            raise AssertionError("the connection was reset without an answer") from None


def test_request_headers_have_a_size_and_a_count_limit(strict: ServerThread) -> None:
    start = b"GET /robot.json HTTP/1.1\r\nHost: 127.0.0.1\r\n"
    huge = start + b"X-Big: " + b"a" * (4 * 1024 * 1024) + b"\r\n\r\n"  # 4 MiB in one header
    answer = _refused_head(strict.port, huge)
    assert answer.startswith(b"HTTP/1.1 431"), answer[:80]
    assert b"at most 64 KiB and 100 lines" in answer
    many = start + b"".join(b"X-%d: 1\r\n" % i for i in range(200)) + b"\r\n"
    assert _refused_head(strict.port, many).startswith(b"HTTP/1.1 431")
    # what browsers and scripts send passes: 95 headers (54 KiB) on a kept-alive connection
    with httpx.Client(base_url=strict.url, timeout=scaled(WAIT_S)) as http:
        headers = {f"X-{i}": "b" * 600 for i in range(90)}  # and httpx's 5
        for _ in range(2):
            assert http.get("/robot.json", headers=headers).status_code == 200


def test_a_client_that_sends_its_whole_refused_head_first_reads_the_431_then_an_end(
    strict: ServerThread,
) -> None:
    # A client that writes its whole request before reading (the kernel takes 1 MiB at once):
    # closing with the rest of the head unread reset the connection after the answer (10 of 10
    # before the lingering close), and could lose the answer itself.
    head = (
        b"GET /robot.json HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Big: " + b"a" * (1 << 20) + b"\r\n\r\n"
    )
    for _ in range(3):
        with socket.create_connection(("127.0.0.1", strict.port)) as sock:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, 8 << 20)
            sock.sendall(head)
            time.sleep(0.3)  # the server has read its 64 KiB and answered meanwhile
            try:
                answer = _closed_within(sock, scaled(WAIT_S))
            except ConnectionResetError:
                raise AssertionError("the answer was followed by a reset, not an end") from None
        assert answer.startswith(b"HTTP/1.1 431"), answer[:80]


def test_a_refused_client_that_never_stops_sending_is_closed(
    moves_folder: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(limits, "LINGER_MAX_S", 1.0)
    robot = from_profile("ergo-jr", sim=True)
    server = ServerThread(create_app(robot), header_timeout_s=0.5).start()
    try:
        with socket.create_connection(("127.0.0.1", server.port)) as sock:
            sock.sendall(b"GET /robot.json HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Big: " + b"a" * 70000)
            closed = False
            deadline = time.monotonic() + scaled(WAIT_S)
            while not closed and time.monotonic() < deadline:  # a byte every 0.1 s, for ever
                try:
                    sock.sendall(b"a")
                except (BrokenPipeError, ConnectionResetError):
                    closed = True
                time.sleep(0.1)
            assert closed, "the server kept a refused connection open while the client sent"
    finally:
        server.stop()
        robot.close()
