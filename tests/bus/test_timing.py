"""Timeout maths and the deadline helper (pure functions)."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from poppy_core.bus.timing import (
    MIN_MARGIN_S,
    SERIAL_LATENCY_S,
    VIRTUAL_LATENCY_S,
    Deadline,
    LinkTiming,
    byte_time_s,
    default_latency_s,
    instruction_size,
    is_virtual_port,
    status_size,
)


def test_byte_time_is_ten_bits() -> None:
    assert byte_time_s(1_000_000) == pytest.approx(10e-6)
    assert byte_time_s(9_600) == pytest.approx(10 / 9600)


def test_packet_sizes_match_the_e_manual_examples() -> None:
    # Protocol 1 ping: FF FF 01 02 01 FB (6 bytes); read of 2 bytes answers 8 bytes.
    assert instruction_size(1, 0) == 6
    assert status_size(1, 2) == 8
    # Protocol 2 ping: 10 bytes; its status carries 3 parameters: 14 bytes.
    assert instruction_size(2, 0) == 10
    assert status_size(2, 3) == 14


def test_reply_timeout_adds_wire_delay_latency_and_margin() -> None:
    timing = LinkTiming(1_000_000, return_delay_s=0.0005, latency_s=0.001)
    physical = 6 * 10e-6 + 0.0005 + 8 * 10e-6 + 0.001
    timeout = timing.reply_timeout_s(6, 8)
    assert physical + MIN_MARGIN_S < timeout < physical * 1.2 + MIN_MARGIN_S


def test_timeout_is_not_a_flat_constant() -> None:
    fast = LinkTiming(1_000_000, 0.0, 0.001).reply_timeout_s(6, 6)
    slow = LinkTiming(9_600, 0.0, 0.001).reply_timeout_s(6, 6)
    assert fast < 0.003
    assert slow > 0.012  # 12 bytes at 9600 bps take 12.5 ms
    assert LinkTiming(1_000_000, 0.0, 0.016).reply_timeout_s(6, 6) > fast + 0.014


def test_several_replies_each_add_a_return_delay() -> None:
    timing = LinkTiming(1_000_000, return_delay_s=0.001, latency_s=0.0)
    one = timing.reply_timeout_s(10, 8)
    three = timing.reply_timeout_s(10, [8, 8, 8])
    assert three - one > 2 * (0.001 + 8 * 10e-6)


@given(
    baud=st.sampled_from([9600, 57600, 115200, 1_000_000, 4_500_000]),
    tx=st.integers(6, 300),
    rx=st.integers(6, 300),
    delay=st.floats(0, 0.0005),
    latency=st.floats(0, 0.016),
)
def test_timeout_always_covers_the_physical_time(
    baud: int, tx: int, rx: int, delay: float, latency: float
) -> None:
    timing = LinkTiming(baud, delay, latency)
    physical = (tx + rx) * 10 / baud + delay + latency
    assert timing.reply_timeout_s(tx, rx) >= physical + MIN_MARGIN_S
    assert timing.grace_s(rx) >= rx * 10 / baud + latency
    assert timing.quiet_gap_s(rx) >= delay + rx * 10 / baud + latency


def test_deadline_expires_and_extends() -> None:
    deadline = Deadline(0.05)
    assert not deadline.expired()
    left = deadline.time_left()
    assert left is not None and 0 < left <= 0.05
    deadline.extend(10.0)
    left = deadline.time_left()
    assert left is not None and left > 9
    assert Deadline(0).expired()
    never = Deadline(None)
    assert never.time_left() is None and not never.expired() and never.infinite


def test_deadline_extend_never_shortens() -> None:
    deadline = Deadline(10.0)
    deadline.extend(0.001)
    left = deadline.time_left()
    assert left is not None and left > 9


def test_expired_deadline_reports_zero_left() -> None:
    deadline = Deadline(0.001)
    time.sleep(0.005)
    assert deadline.expired()
    assert deadline.time_left() == 0.0


def test_virtual_ports() -> None:
    assert is_virtual_port("socket://127.0.0.1:4000")
    assert is_virtual_port("loop://")
    assert is_virtual_port("/dev/pts/3")
    assert not is_virtual_port("/dev/ttyUSB0")


def _fake_sysfs(root: Path, tty: str, latency: str) -> str:
    folder = root / "bus" / "usb-serial" / "devices" / tty
    folder.mkdir(parents=True)
    (folder / "latency_timer").write_text(latency + "\n")
    return str(root)


def test_default_latency_from_ftdi_sysfs(tmp_path: Path) -> None:
    sysfs = _fake_sysfs(tmp_path, "ttyUSB0", "16")
    assert default_latency_s("/dev/ttyUSB0", sysfs_root=sysfs) == pytest.approx(0.016)


def test_default_latency_other_devices_and_urls(tmp_path: Path) -> None:
    assert default_latency_s("/dev/ttyACM0", sysfs_root=str(tmp_path)) == SERIAL_LATENCY_S
    assert default_latency_s("socket://localhost:1", sysfs_root=str(tmp_path)) == VIRTUAL_LATENCY_S
    master, slave = os.openpty()
    try:
        assert default_latency_s(os.ttyname(slave)) == VIRTUAL_LATENCY_S
    finally:
        os.close(master)
        os.close(slave)
