"""The cost of signed requests on Zenoh (``zenoh_auth``), for ``python -m bench fleet``.

1. **Sign and check**: what a signed request adds per request, alone: the client's signing
   (``zenoh_wire.api_request`` with a token) and the robot's check (``Intake.api``: the HMAC,
   the window, the nonce) against the same request unsigned, over ``OPS`` requests, in the
   thread's CPU time (``time.thread_time``): on a shared machine the wall-clock p99 of a 40 µs
   step is the scheduler's time slice (a preemption in 1 % of them), not the step's cost.
2. **Round trip**: ``GET /api/v1/motors`` over Zenoh to two robots served in this process, one
   with a token (signed requests) and one without, interleaved request by request (so that a
   neighbour's load falls on both alike), ``TRIPS`` each.
3. **Unsigned flood**: ``FLOOD`` unsigned starts due 50 s ahead, sent at once to the robot with
   a token: how long until every one is answered (401, on arrival), and the process's resident
   memory before and after (robot and client share it).
"""

from __future__ import annotations

import time
from typing import Any

from bench.side_by_side import percentile

OPS = 5000
TRIPS = 400
FLOOD = 300
TOKEN = "a-bench-token-0123456789abcdef"


def _ms(values: list[float], q: float) -> float:
    return (percentile(sorted(values), q) or 0.0) * 1000


def sign_and_check() -> dict[str, Any]:
    from poppy_core import zenoh_wire
    from poppy_core.server.zenoh.intake import Intake

    signed, plain = Intake("jr-a", TOKEN, max_armed=1), Intake("jr-a", None, max_armed=1)
    signed.verifier.max_nonces = OPS + 10  # type: ignore[union-attr]
    body = {"positions": {"m1": 10.0, "m2": -5.0}, "duration_s": 1.0}
    times: dict[str, list[float]] = {"signed": [], "plain": []}
    for _ in range(OPS):
        for label, intake, token in (("signed", signed, TOKEN), ("plain", plain, None)):
            began = time.thread_time()
            payload = zenoh_wire.api_request(
                "POST", "/api/v1/gotos", body, token=token, robot="jr-a", sender="bench"
            )
            intake.api(payload)
            times[label].append(time.thread_time() - began)
    return {
        "ops": OPS,
        **{f"{k}_p50_ms": _ms(v, 0.5) for k, v in times.items()},
        **{f"{k}_p99_ms": _ms(v, 0.99) for k, v in times.items()},
        "added_p50_ms": _ms(times["signed"], 0.5) - _ms(times["plain"], 0.5),
        "added_p99_ms": _ms(times["signed"], 0.99) - _ms(times["plain"], 0.99),
    }


def round_trip() -> dict[str, Any]:
    """``{"trip": the interleaved round trips, "flood": flood()}`` on two robots served here."""
    import socket

    from poppy_core import from_profile
    from poppy_core.assembly import ServeSpec, ZenohSettings, serve
    from poppy_core.remote.zenoh_client import ZenohClient

    def endpoint() -> str:
        with socket.socket() as sock:
            sock.bind(("127.0.0.1", 0))
            return f"tcp/127.0.0.1:{sock.getsockname()[1]}"

    served = []
    clients: dict[str, Any] = {}
    try:
        for label, token in (("signed", TOKEN), ("plain", None)):
            where = endpoint()
            robot = from_profile("ergo-jr", sim=True)
            spec = ServeSpec(zenoh=ZenohSettings(listen=(where,)), name=f"b-{label}", token=token)
            served.append((robot, serve(robot, spec)))
            settings = ZenohSettings(connect=(where,))
            clients[label] = ZenohClient(f"b-{label}", token, 5.0, settings=settings)
        flooded = flood(clients, "b-signed")
        times: dict[str, list[float]] = {"signed": [], "plain": []}
        for index in range(TRIPS + 20):
            for label, client in clients.items():
                began = time.perf_counter()
                status, _ = client.call("GET", "/api/v1/motors")
                elapsed = time.perf_counter() - began
                assert status == 200, status
                if index >= 20:  # the first ones warm the routes up
                    times[label].append(elapsed)
    finally:
        for client in clients.values():
            client.close()
        for robot, servers in served:
            servers.stop()
            robot.close()
    trip = {
        "trips": TRIPS,
        **{f"{k}_p50_ms": _ms(v, 0.5) for k, v in times.items()},
        **{f"{k}_p99_ms": _ms(v, 0.99) for k, v in times.items()},
        "added_p50_ms": _ms(times["signed"], 0.5) - _ms(times["plain"], 0.5),
        "added_p99_ms": _ms(times["signed"], 0.99) - _ms(times["plain"], 0.99),
    }
    return {"trip": trip, "flood": flooded}


def _rss_mib() -> float:
    with open("/proc/self/status", encoding="ascii") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return 0.0


def flood(clients: dict[str, Any], robot: str) -> dict[str, Any]:
    """``FLOOD`` unsigned starts due 50 s ahead to ``robot`` (one with a token), at once."""
    import json

    from poppy_core import zenoh_wire

    session = clients["signed"].session
    before = _rss_mib()
    start_at = time.time() + 50.0
    payload = zenoh_wire.api_request("POST", "/api/v1/primitives/dance/start", start_at=start_at)
    key = zenoh_wire.robot_key(robot, "api")
    began = time.perf_counter()
    handlers = [session.get(key, payload=payload, timeout=45.0) for _ in range(FLOOD)]
    statuses = set()
    for handler in handlers:
        for reply in handler:
            if reply.ok is not None:
                statuses.add(json.loads(reply.ok.payload.to_bytes())["status"])
    return {
        "requests": FLOOD,
        "answered_s": time.perf_counter() - began,
        "before_start": time.time() < start_at,
        "statuses": sorted(statuses),
        "rss_added_mib": _rss_mib() - before,
    }


def signed_requests() -> dict[str, Any]:
    """The three measures: ``check``, ``trip`` and ``flood``."""
    return {"check": sign_and_check(), **round_trip()}


if __name__ == "__main__":
    import json

    print(json.dumps(signed_requests(), indent=2))
