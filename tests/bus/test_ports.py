"""Port listing with fake port records and a fake sysfs tree."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import pytest

from poppy_core.bus import ports as ports_module
from poppy_core.bus.ports import (
    describe_ports,
    latency_advice,
    list_ports,
    port_info,
    read_ftdi_latency_ms,
    recognise_adapter,
)


@dataclass
class FakeRecord:
    device: str
    description: str = "n/a"
    vid: int | None = None
    pid: int | None = None
    serial_number: str | None = None


def _sysfs(root: Path, tty: str, latency_ms: int) -> str:
    folder = root / "bus" / "usb-serial" / "devices" / tty
    folder.mkdir(parents=True)
    (folder / "latency_timer").write_text(f"{latency_ms}\n")
    return str(root)


def _allowed(path: str, mode: int) -> bool:
    return True


def _denied(path: str, mode: int) -> bool:
    return False


@pytest.mark.parametrize(
    ("vid", "pid", "name"),
    [
        (0x16D0, 0x06A7, "USB2AX"),
        (0x0403, 0x6014, "U2D2"),
        (0x0403, 0x6001, "USB2Dynamixel"),
        (0x0403, 0x6015, "FTDI adapter"),
        (0x2341, 0x0043, None),
        (None, None, None),
    ],
)
def test_recognise_adapter(vid: int | None, pid: int | None, name: str | None) -> None:
    assert recognise_adapter(vid, pid) == name


def test_u2d2_with_slow_latency_gets_advice(tmp_path: Path) -> None:
    sysfs = _sysfs(tmp_path, "ttyUSB0", 16)
    record = FakeRecord("/dev/ttyUSB0", "U2D2", 0x0403, 0x6014, "FT1234")
    info = port_info(record, sysfs_root=sysfs, access=_allowed, platform="linux")
    assert info.adapter == "U2D2"
    assert info.latency_timer_ms == 16
    assert info.usb_id == "0403:6014"
    assert info.accessible
    assert len(info.advice) == 1
    assert "echo 1 | sudo tee /sys/bus/usb-serial/devices/ttyUSB0/latency_timer" in info.advice[0]
    assert "16 ms" in info.advice[0]


def test_latency_one_ms_needs_no_advice(tmp_path: Path) -> None:
    sysfs = _sysfs(tmp_path, "ttyUSB1", 1)
    record = FakeRecord("/dev/ttyUSB1", "FT232R", 0x0403, 0x6001)
    info = port_info(record, sysfs_root=sysfs, access=_allowed, platform="linux")
    assert info.adapter == "USB2Dynamixel"
    assert info.latency_timer_ms == 1
    assert info.advice == []


def test_usb2ax_has_no_latency_timer(tmp_path: Path) -> None:
    record = FakeRecord("/dev/ttyACM0", "USB2AX", 0x16D0, 0x06A7)
    info = port_info(record, sysfs_root=str(tmp_path), access=_allowed, platform="linux")
    assert info.adapter == "USB2AX"
    assert info.latency_timer_ms is None
    assert info.advice == []


def test_inaccessible_port_gets_dialout_advice(tmp_path: Path) -> None:
    record = FakeRecord("/dev/ttyACM0", "USB2AX", 0x16D0, 0x06A7)
    info = port_info(record, sysfs_root=str(tmp_path), access=_denied, platform="linux")
    assert not info.accessible
    assert any("sudo usermod -aG dialout $USER" in hint for hint in info.advice)


def test_missing_or_garbled_sysfs_gives_none(tmp_path: Path) -> None:
    assert read_ftdi_latency_ms("/dev/ttyUSB7", sysfs_root=str(tmp_path)) is None
    folder = tmp_path / "bus" / "usb-serial" / "devices" / "ttyUSB8"
    folder.mkdir(parents=True)
    (folder / "latency_timer").write_text("garbage")
    assert read_ftdi_latency_ms("/dev/ttyUSB8", sysfs_root=str(tmp_path)) is None
    assert latency_advice("/dev/ttyUSB8", None) is None


def test_adapters_are_listed_first(tmp_path: Path) -> None:
    records = [
        FakeRecord("/dev/ttyS0", "ttyS0"),
        FakeRecord("/dev/ttyUSB0", "U2D2", 0x0403, 0x6014),
        FakeRecord("/dev/ttyACM0", "Arduino", 0x2341, 0x0043),
    ]
    infos = describe_ports(records, sysfs_root=str(tmp_path), access=_allowed, platform="linux")
    assert [i.device for i in infos] == ["/dev/ttyUSB0", "/dev/ttyACM0", "/dev/ttyS0"]


def test_list_ports_uses_comports(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    from serial.tools import list_ports as serial_list_ports

    fake = [FakeRecord("/dev/ttyUSB3", "U2D2", 0x0403, 0x6014)]
    monkeypatch.setattr(serial_list_ports, "comports", lambda: fake)
    _sysfs(tmp_path, "ttyUSB3", 16)
    infos = list_ports(sysfs_root=str(tmp_path))
    assert [i.device for i in infos] == ["/dev/ttyUSB3"]
    assert infos[0].latency_timer_ms == 16
    assert ports_module.DIALOUT_ADVICE.startswith("add yourself")


def test_symlinked_device_resolves_to_tty(tmp_path: Path) -> None:
    sysfs = _sysfs(tmp_path / "sys", "ttyUSB4", 8)
    target = tmp_path / "ttyUSB4"
    target.write_text("")
    link = tmp_path / "usb-FTDI_U2D2-if00-port0"
    os.symlink(target, link)
    assert read_ftdi_latency_ms(str(link), sysfs_root=sysfs) == 8
