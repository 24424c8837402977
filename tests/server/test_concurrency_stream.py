"""A waiting goto blocks nobody; the WebSocket streams at its rate and takes checked commands."""

from __future__ import annotations

import json
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import httpx
import pytest
from websockets.sync.client import connect

from tests.helpers.server import Served
from tests.helpers.waiting import eventually, http_timeout, scaled


def test_gets_are_answered_while_a_waiting_goto_runs(served: Served, client: httpx.Client) -> None:
    # The GETs are answered while the waiting goto still runs (how fast: `python -m bench
    # timing`); the goto outlasts them on a loaded machine too: 1.5 s times the load factor.
    served.robot.m1.compliant = False
    result: dict[str, Any] = {}
    goto_s = scaled(1.5)
    before = served.robot.m1.goal_position
    target = -30.0 if before > 0 else 30.0

    def slow_goto() -> None:
        with httpx.Client(base_url=served.url, timeout=http_timeout(10.0) + goto_s) as http:
            t0 = time.monotonic()
            body = {"position": target, "duration": goto_s, "wait": True}
            result["answer"] = http.post("/motors/m1/goto.json", json=body)
            result["elapsed"] = time.monotonic() - t0

    mover = threading.Thread(target=slow_goto)
    mover.start()
    assert eventually(lambda: abs(served.robot.m1.goal_position - before) > 0.1)  # it runs

    def get(_: int) -> int:
        return client.get("/motors/m1/registers/present_position/value.json").status_code

    with ThreadPoolExecutor(8) as pool:
        statuses = list(pool.map(get, range(40)))
    assert mover.is_alive(), "the GETs should be answered while the waiting goto runs"
    mover.join()
    assert statuses == [200] * 40
    assert result["answer"].status_code == 202
    assert result["elapsed"] >= goto_s - 0.1  # answered once the motion is over, never before
    served.robot.compliant = True


def test_v1_waiting_goto_does_not_block_either(client: httpx.Client, served: Served) -> None:
    served.robot.m2.compliant = False
    goto_s = scaled(3.0)  # outlasts the GET on a loaded machine too
    with ThreadPoolExecutor(1) as pool:
        body = {"positions": {"m2": 20}, "duration_s": goto_s, "wait": True}
        wait_s = goto_s + scaled(10.0)
        future = pool.submit(
            lambda: httpx.post(f"{served.url}/api/v1/gotos", json=body, timeout=wait_s)
        )
        time.sleep(0.2)
        assert client.get("/api/v1/robot/state").status_code == 200
        assert not future.done()  # answered while the goto still waits, not after it
        answer = future.result(timeout=wait_s)
    assert answer.status_code == 200
    assert answer.json()["done"] is True
    served.robot.compliant = True


def _ws_url(served: Served, query: str = "") -> str:
    return served.url.replace("http://", "ws://") + "/api/v1/ws" + query


@pytest.mark.parametrize("rate_hz", [10.0, 30.0])
def test_stream_rate(served: Served, rate_hz: float) -> None:
    with connect(_ws_url(served, f"?rate_hz={rate_hz}")) as ws:
        ws.recv(timeout=2)
        t0 = time.monotonic()
        count = 0
        while time.monotonic() - t0 < 1.0:
            frame = json.loads(ws.recv(timeout=2))
            count += 1
    assert set(frame) == {"m1", "m2", "m3", "m4", "m5", "m6"}
    assert set(frame["m1"]) == {
        "present_position",
        "present_speed",
        "present_load",
        "present_temperature",
        "led",
    }
    assert rate_hz * 0.6 <= count <= rate_hz * 1.4


def test_stream_keeps_its_rate_under_http_load(served: Served) -> None:
    stop = threading.Event()

    def hammer() -> None:
        with httpx.Client(base_url=served.url, timeout=http_timeout(10.0)) as http:
            while not stop.is_set():
                http.get("/robot.json")

    workers = [threading.Thread(target=hammer) for _ in range(4)]
    for worker in workers:
        worker.start()
    try:
        with connect(_ws_url(served, "?rate_hz=20")) as ws:
            ws.recv(timeout=2)
            t0 = time.monotonic()
            count = 0
            while time.monotonic() - t0 < 1.0:
                ws.recv(timeout=2)
                count += 1
    finally:
        stop.set()
        for worker in workers:
            worker.join()
    assert count >= 10


def test_stream_commands_are_checked(served: Served) -> None:
    with connect(_ws_url(served)) as ws:
        ws.send(json.dumps({"m4": {"led": "red"}}))
        deadline = time.monotonic() + 2
        while served.robot.m4.led != "red" and time.monotonic() < deadline:
            ws.recv(timeout=2)
        assert served.robot.m4.led == "red"
        before = served.robot.m4.goal_position
        ws.send(json.dumps({"m4": {"goal_position": 1e12}, "m5": {"led": "blue"}}))  # beyond ±1e9
        ws.send("not json")
        errors = []
        while len(errors) < 2 and time.monotonic() < deadline + 2:
            frame = json.loads(ws.recv(timeout=2))
            if "error" in frame:
                errors.append(frame["error"])
        assert "goal_position" in errors[0]
        assert "JSON" in errors[1]
        assert served.robot.m4.goal_position == before
        assert served.robot.m5.led != "blue"
    served.robot.m4.led = "off"
