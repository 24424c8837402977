"""TCP serving, specs, line speed, timing helpers and fault knobs."""

from __future__ import annotations

import os
import threading
import time

import pytest
import serial
from emulator_client import RawClient

from poppy_core.emulator import (
    EmulatorConfig,
    FaultInjector,
    baud_matches,
    build_bus_from_spec,
    ergo_jr_bus,
    parse_spec,
    read_pty_baudrate,
    serve_pty,
    serve_tcp,
    sleep_until,
    transfer_time_s,
)
from poppy_core.emulator.wire_timing import LineClock
from poppy_core.errors import ConfigError, PortError
from poppy_core.protocol import ping, read


def test_tcp_serving() -> None:
    bus = build_bus_from_spec("MX-28:11-12")
    with serve_tcp(bus) as server:
        assert server.url.startswith("socket://127.0.0.1:")
        client = RawClient(server.url, 1)
        assert [r.id for r in client.transact(ping(12))] == [12]
        (reply,) = client.transact(read(1, 11, 3, 1))
        assert reply.params == b"\x0b"
        client.close()
        # a second client after the first went away
        client = RawClient(server.url, 1)
        assert [r.id for r in client.transact(ping(11))] == [11]
        client.close()
    assert not server.running


def test_tcp_line_speed_is_the_bus_baudrate() -> None:
    bus = build_bus_from_spec("XL-320:1", baudrate=57_600)
    with serve_tcp(bus) as server:
        client = RawClient(server.url, 2)
        assert [r.id for r in client.transact(ping(1))] == [1]
        client.close()


def test_tcp_port_in_use_is_a_port_error() -> None:
    bus = build_bus_from_spec("XL-320:1")
    with serve_tcp(bus) as server:
        port = int(server.url.rsplit(":", 1)[1])
        with pytest.raises(PortError):
            serve_tcp(bus, port=port)


def test_pty_server_stops_cleanly() -> None:
    server = serve_pty(ergo_jr_bus())
    assert os.path.exists(server.url) and server.running
    server.stop()
    server.stop()
    assert not server.running
    assert threading.active_count() < 50


def test_pty_reports_client_baudrate() -> None:
    master, slave = os.openpty()
    try:
        for rate in (57_600, 1_000_000, 2_250_000, 3_000_000):
            port = serial.Serial(os.ttyname(slave), rate)
            assert read_pty_baudrate(slave) == rate
            port.close()
    finally:
        os.close(master)
        os.close(slave)


def test_baud_matches() -> None:
    assert baud_matches(57_600, 57_142)  # protocol 1 code 34: 2 M / 35
    assert baud_matches(1_000_000, 1_000_000)
    assert not baud_matches(115_200, 1_000_000)
    assert not baud_matches(1_000_000, 0)


def test_timing_helpers() -> None:
    assert transfer_time_s(10, 1_000_000) == pytest.approx(100e-6)
    clock = LineClock()
    assert clock.receive(10, 1.0, 100_000) == pytest.approx(1.001)
    assert clock.receive(10, 1.0005, 100_000) == pytest.approx(1.002)  # line still busy
    deadline = time.perf_counter() + 0.003
    sleep_until(deadline)
    assert time.perf_counter() >= deadline


def test_fault_injector_is_reproducible() -> None:
    def run(seed: int) -> list[bytes | None]:
        faults = FaultInjector(seed)
        faults.corrupt_rate = 0.1
        faults.drop_rate = 0.2
        return [faults.filter_reply(bytes(20)) for _ in range(50)]

    assert run(3) == run(3)
    results = run(3)
    assert any(r is None for r in results)
    assert any(r is not None and r != bytes(20) for r in results)
    with pytest.raises(ValueError):
        FaultInjector().drop_rate = 1.5
    with pytest.raises(ValueError):
        FaultInjector().extra_delay_s = -1


def test_parse_spec() -> None:
    pairs = parse_spec("MX-28:11-13,AX-12A:36+38, 40")
    assert [(m.name, i) for m, i in pairs] == [
        ("MX-28", 11),
        ("MX-28", 12),
        ("MX-28", 13),
        ("AX-12A", 36),
        ("AX-12A", 38),
        ("AX-12A", 40),
    ]


def test_a_kit_spec_shares_an_id() -> None:
    pairs = parse_spec("XL-320:1*3,4")
    assert [(m.name, i) for m, i in pairs] == [("XL-320", 1)] * 3 + [("XL-320", 4)]


@pytest.mark.parametrize(
    "spec",
    [
        "",
        "MX-28",
        "NOPE-1:1",
        "MX-28:5-2",
        "MX-28:1,MX-28:1",
        "MX-28:x",
        "1-3",
        "MX-28:300",
        "XL-320:1*0",
        "XL-320:300*2",
        "XL-320:1*2,1",
    ],
)
def test_bad_specs(spec: str) -> None:
    with pytest.raises(ConfigError) as info:
        parse_spec(spec)
    assert info.value.field == "spec"


def test_spec_protocol_checks() -> None:
    with pytest.raises(ConfigError):
        build_bus_from_spec("MX-28:1,XL-320:2")
    with pytest.raises(ConfigError):
        build_bus_from_spec("MX-28:1", protocol=2)
    with pytest.raises(ConfigError):
        build_bus_from_spec("XL-320:1", baudrate=3_000_000)  # XL-320 tops out at 1 Mbps


def test_ergo_jr_bus() -> None:
    bus = ergo_jr_bus()
    assert bus.protocol == 2 and bus.baudrate == 1_000_000
    assert [(m.model.name, m.id, m.baudrate_bps) for m in bus.motors] == [
        ("XL-320", i, 1_000_000) for i in range(1, 7)
    ]


def test_emulator_config_builds_a_bus() -> None:
    bus = EmulatorConfig("AX-12A:1-2", baudrate=57_600, adapter="usb2ax", latency_s=0.001).build()
    assert bus.adapter == "usb2ax" and bus.latency_s == 0.001
    assert [m.baudrate_bps for m in bus.motors] == [57_600, 57_600]
    assert bus.process(b"\xff\xff\xfe\x02\x01\xfe") == b""  # v1 broadcast ping: silence


def test_serving_on_a_port_out_of_range_is_a_port_error() -> None:
    import pytest

    from poppy_core.emulator import build_bus_from_spec, serve_tcp
    from poppy_core.errors import PortError

    with pytest.raises(PortError, match=r"cannot listen on 127\.0\.0\.1:99999"):
        serve_tcp(build_bus_from_spec("XL-320:1"), "127.0.0.1", 99999)
