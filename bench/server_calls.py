"""Python calls and CPU per request of ``poppy serve --http --sim``, counted without a network.

Run by a checkout's own interpreter, from that checkout (``PYTHONPATH=DIR python -c SOURCE OUT
[N] [TOP]``; ``bench.server_bench`` passes this file's source), so it imports only the standard
library and uvicorn. It starts the checkout's real ``poppy serve --sim --profile ergo-jr --http``
(its robot, sync loops, app and uvicorn settings), takes the uvicorn config that server loaded,
and drives a second instance of the same HTTP protocol class over an in-memory transport on a
loop of its own (made as uvicorn makes the server's: uvloop when installed). Every request goes
through uvicorn's parser, the connection limits, every middleware, the route and the answer's
encoding, as over a socket, minus the kernel.

For each route: ``calls`` is the Python and C function calls cProfile counts per request
(deterministic: the same code answers the same request the same way), ``cpu_us`` this thread's
CPU per request without the profiler (``time.thread_time``; load moves it a little, unlike
the calls). ``/robot.json`` is counted twice: its 10 ms cache always hit, and rebuilt for every
request. The JSON written to OUT maps each route to its figures; with TOP, the TOP functions
called most per request are added with the µs spent in each (for profiling).
"""

from __future__ import annotations

import asyncio
import contextlib
import cProfile
import json
import os
import pstats
import runpy
import signal
import socket
import sys
import threading
import time
from typing import Any

REGISTER = "/motors/m1/registers/present_position/value.json"
GOAL = "/motors/m1/registers/goal_position/value.json"
GOTO = json.dumps({"motors": ["m2"], "positions": [20], "duration": 1.0, "wait": False})
ROUTES: dict[str, tuple[str, str, str, float | None]] = {
    # name: method, path, body, /robot.json cache lifetime (None: as served)
    "register GET": ("GET", REGISTER, "", None),
    "/robot.json (cached)": ("GET", "/robot.json", "", 1e9),
    "/robot.json (rebuilt)": ("GET", "/robot.json", "", -1.0),
    "goal POST": ("POST", GOAL, "10", None),
    "goto POST": ("POST", "/motors/goto.json", GOTO, None),
    "motors list": ("GET", "/motors/list.json", "", None),
}
WARMUP = 50
START_TIMEOUT_S = 120.0

captured: dict[str, Any] = {}
ready = threading.Event()


def _capture() -> None:
    """Keep the uvicorn server the checkout builds (its config holds the app and protocol)."""
    import uvicorn

    original = uvicorn.Server.__init__

    def init(self: Any, config: Any) -> None:
        original(self, config)
        captured.setdefault("server", self)
        ready.set()

    uvicorn.Server.__init__ = init  # type: ignore[method-assign]


class Transport(asyncio.Transport):
    """A connection that keeps what the server writes."""

    def __init__(self) -> None:
        super().__init__()
        self.written: list[bytes] = []
        self.closed = False

    def get_extra_info(self, name: str, default: Any = None) -> Any:
        return {"sockname": ("127.0.0.1", 8080), "peername": ("127.0.0.1", 40000)}.get(
            name, default
        )

    def write(self, data: Any) -> None:
        self.written.append(bytes(data))

    def is_closing(self) -> bool:
        return self.closed

    def close(self) -> None:
        self.closed = True

    def pause_reading(self) -> None:
        pass

    def resume_reading(self) -> None:
        pass


def _request(method: str, path: str, body: str) -> bytes:
    """The request as wrk sends it (the bench's load)."""
    head = f"{method} {path} HTTP/1.1\r\nHost: 127.0.0.1:8080\r\nContent-Type: application/json\r\n"
    if body:
        head += f"Content-Length: {len(body.encode())}\r\n"
    return (head + "\r\n" + body).encode()


def _connection(config: Any, loop: asyncio.AbstractEventLoop) -> tuple[Any, Transport, list[Any]]:
    from uvicorn.server import ServerState

    waiting: list[Any] = []

    class Counted(config.http_protocol_class):  # type: ignore[misc]
        def on_response_complete(self) -> None:
            super().on_response_complete()
            if waiting:
                waiting.pop().set_result(None)

    protocol = Counted(config=config, server_state=ServerState(), app_state={}, _loop=loop)
    transport = Transport()
    protocol.connection_made(transport)
    return protocol, transport, waiting


def _route(config: Any, route: str, count: int, top: int) -> dict[str, Any]:
    method, path, body, ttl = ROUTES[route]
    # the description's time to live: in service.py up to stop 35, then service_primitives.py
    service_module: Any = sys.modules.get(
        "poppy_core.server.service_primitives", sys.modules["poppy_core.server.service"]
    )
    served_ttl = service_module.DESCRIPTION_TTL_S
    if ttl is not None:
        service_module.DESCRIPTION_TTL_S = ttl
    factory = config.get_loop_factory() if hasattr(config, "get_loop_factory") else None
    loop = factory() if factory is not None else asyncio.new_event_loop()  # uvloop, as served
    protocol, transport, waiting = _connection(config, loop)
    data = _request(method, path, body)

    async def drive(n: int) -> None:
        for _ in range(n):
            done = loop.create_future()
            waiting.append(done)
            protocol.data_received(data)
            await done

    try:
        loop.run_until_complete(drive(WARMUP))
        answer = b"".join(transport.written[-2:])
        status = int(transport.written[0].split(b" ", 2)[1])
        cpu0 = time.thread_time()
        loop.run_until_complete(drive(count))
        cpu_us = (time.thread_time() - cpu0) / count * 1e6
        profile = cProfile.Profile()
        profile.enable()
        loop.run_until_complete(drive(count))
        profile.disable()
    finally:
        service_module.DESCRIPTION_TTL_S = served_ttl
        protocol.connection_lost(None)
        loop.close()
    stats = pstats.Stats(profile).stats  # type: ignore[attr-defined]
    calls = sum(entry[1] for entry in stats.values())
    result: dict[str, Any] = {
        "calls": calls / count,
        "cpu_us": cpu_us,
        "status": status,
        "answer_bytes": len(answer),
    }
    if top:
        most = sorted(stats.items(), key=lambda item: -item[1][1])[:top]
        result["top"] = [
            [
                round(entry[1] / count, 2),
                round(entry[2] / count * 1e6, 2),  # µs inside it, the profiler's cost included
                f"{where[0].rsplit('/', 2)[-1]}:{where[1]}({where[2]})",
            ]
            for where, entry in most
        ]
    return result


def _drive(out: str, count: int, top: int) -> None:
    try:
        if not ready.wait(START_TIMEOUT_S):
            raise RuntimeError("the server was not built in time")
        server = captured["server"]
        deadline = time.monotonic() + START_TIMEOUT_S
        while not server.started:
            if time.monotonic() > deadline:
                raise RuntimeError("the server did not start in time")
            time.sleep(0.05)
        results = {route: _route(server.config, route, count, top) for route in ROUTES}
        with open(out, "w") as file:
            json.dump(results, file)
    except BaseException as exc:
        with open(out, "w") as file:
            json.dump({"error": f"{type(exc).__name__}: {exc}"}, file)
    finally:
        os.kill(os.getpid(), signal.SIGTERM)


def main() -> None:
    out = sys.argv[1]
    count = int(sys.argv[2]) if len(sys.argv) > 2 else 500
    top = int(sys.argv[3]) if len(sys.argv) > 3 else 0
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    _capture()
    threading.Thread(target=_drive, args=(out, count, top), daemon=True).start()
    sys.argv = ["poppy", "serve", "--sim", "--profile", "ergo-jr", "--http", "--http-port"]
    sys.argv.append(str(port))
    with contextlib.suppress(SystemExit):
        runpy.run_module("poppy_cli", run_name="__main__", alter_sys=True)


if __name__ == "__main__":
    main()
