"""Serial port listing: adapter recognition by USB VID:PID, FTDI latency timer, access advice."""

from __future__ import annotations

import logging
import os
import sys
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Protocol

logger = logging.getLogger(__name__)

# USB identifiers of the usual Dynamixel adapters (vendor id, product id) -> name.
# USB2AX (Xevelabs): 16d0:06a7. U2D2 (Robotis): FTDI FT232H, 0403:6014.
# USB2Dynamixel (Robotis): FTDI FT232R, 0403:6001.
KNOWN_ADAPTERS: dict[tuple[int, int], str] = {
    (0x16D0, 0x06A7): "USB2AX",
    (0x0403, 0x6014): "U2D2",
    (0x0403, 0x6001): "USB2Dynamixel",
}
FTDI_VENDOR_ID = 0x0403

# The FTDI driver holds received bytes up to this many ms before passing them on (kernel default
# 16 ms); 1 ms is what a Dynamixel bus wants.
GOOD_LATENCY_MS = 1

DIALOUT_ADVICE = (
    "add yourself to the dialout group: sudo usermod -aG dialout $USER, then log in again"
)


class PortRecord(Protocol):
    """What ``port_info`` needs from a port record (pyserial's ``ListPortInfo`` fits)."""

    device: str
    description: str
    vid: int | None
    pid: int | None
    serial_number: str | None


@dataclass(frozen=True)
class PortInfo:
    """One serial port as poppy sees it.

    Attributes:
        device: path to open (``/dev/ttyUSB0``, ``COM3``).
        description: the OS's description of the port.
        vid: USB vendor id, None for a non-USB port.
        pid: USB product id.
        serial_number: USB serial number when known.
        adapter: recognised adapter name (``"USB2AX"``, ``"U2D2"``, ``"USB2Dynamixel"``,
            ``"FTDI adapter"``), None when not recognised.
        latency_timer_ms: FTDI latency timer (Linux), None when not applicable or unreadable.
        accessible: whether this user may open the port for reading and writing.
        advice: one-line hints to make the port work well (empty when all is fine).
    """

    device: str
    description: str
    vid: int | None = None
    pid: int | None = None
    serial_number: str | None = None
    adapter: str | None = None
    latency_timer_ms: int | None = None
    accessible: bool = True
    advice: list[str] = field(default_factory=list)

    @property
    def usb_id(self) -> str | None:
        """``"16d0:06a7"`` style identifier, None for a non-USB port."""
        if self.vid is None or self.pid is None:
            return None
        return f"{self.vid:04x}:{self.pid:04x}"


def recognise_adapter(vid: int | None, pid: int | None) -> str | None:
    """Name the Dynamixel adapter with this USB VID:PID, None when unknown.

    Any other FTDI chip is reported as ``"FTDI adapter"`` (many third-party adapters use one).
    """
    if vid is None or pid is None:
        return None
    name = KNOWN_ADAPTERS.get((vid, pid))
    if name is None and vid == FTDI_VENDOR_ID:
        return "FTDI adapter"
    return name


def latency_timer_path(device: str, sysfs_root: str = "/sys") -> str:
    """Where Linux keeps the FTDI latency timer of ``device`` (symlinks resolved)."""
    tty = os.path.basename(os.path.realpath(device))
    return os.path.join(sysfs_root, "bus", "usb-serial", "devices", tty, "latency_timer")


def read_ftdi_latency_ms(device: str, *, sysfs_root: str = "/sys") -> int | None:
    """Read the FTDI latency timer of ``device`` from sysfs (Linux), in ms.

    Args:
        device: ``/dev/ttyUSB0`` (symlinks such as ``/dev/serial/by-id/...`` are resolved).
        sysfs_root: root of the sysfs tree (tests pass a fake one).

    Returns:
        The timer in ms, or None when the file does not exist (not an FTDI device, not Linux)
        or cannot be read.
    """
    path = latency_timer_path(device, sysfs_root)
    try:
        with open(path, encoding="ascii") as handle:
            return int(handle.read().strip())
    except (OSError, ValueError):
        return None


def latency_advice(device: str, latency_ms: int | None) -> str | None:
    """Advice to lower an FTDI latency timer above 1 ms, None when it is fine or unknown."""
    if latency_ms is None or latency_ms <= GOOD_LATENCY_MS:
        return None
    tty = os.path.basename(os.path.realpath(device))
    return (
        f"latency timer is {latency_ms} ms (slow bus): "
        f"echo 1 | sudo tee /sys/bus/usb-serial/devices/{tty}/latency_timer "
        '(or a udev rule: ACTION=="add", SUBSYSTEM=="usb-serial", DRIVER=="ftdi_sio", '
        'ATTR{latency_timer}="1")'
    )


def access_advice(accessible: bool, platform: str = sys.platform) -> str | None:
    """Advice when the port cannot be opened for lack of permission, None when accessible."""
    if accessible:
        return None
    if platform.startswith("linux"):
        return f"permission denied: {DIALOUT_ADVICE}"
    return "permission denied: check that your user may open this serial port"


def port_info(
    record: PortRecord,
    *,
    sysfs_root: str = "/sys",
    access: Callable[[str, int], bool] = os.access,
    platform: str = sys.platform,
) -> PortInfo:
    """Describe one port record (pure apart from the sysfs read and the access check).

    Args:
        record: a pyserial ``ListPortInfo`` or anything with the same attributes.
        sysfs_root: root of the sysfs tree.
        access: ``os.access``-like check (tests pass a fake).
        platform: ``sys.platform``-like string.

    Returns:
        The port's description, adapter name, latency timer and advice.
    """
    adapter = recognise_adapter(record.vid, record.pid)
    latency_ms = None
    if record.vid == FTDI_VENDOR_ID and platform.startswith("linux"):
        latency_ms = read_ftdi_latency_ms(record.device, sysfs_root=sysfs_root)
    accessible = access(record.device, os.R_OK | os.W_OK)
    advice = [
        hint
        for hint in (latency_advice(record.device, latency_ms), access_advice(accessible, platform))
        if hint is not None
    ]
    return PortInfo(
        device=record.device,
        description=record.description,
        vid=record.vid,
        pid=record.pid,
        serial_number=record.serial_number,
        adapter=adapter,
        latency_timer_ms=latency_ms,
        accessible=accessible,
        advice=advice,
    )


def describe_ports(
    records: Iterable[PortRecord],
    *,
    sysfs_root: str = "/sys",
    access: Callable[[str, int], bool] = os.access,
    platform: str = sys.platform,
) -> list[PortInfo]:
    """Describe port records, recognised adapters first, then by device name."""
    infos = [
        port_info(record, sysfs_root=sysfs_root, access=access, platform=platform)
        for record in records
    ]
    return sorted(infos, key=lambda info: (info.adapter is None, info.device))


def list_ports(*, sysfs_root: str = "/sys") -> list[PortInfo]:
    """List the serial ports of this machine (pyserial's ``comports``), adapters first.

    Args:
        sysfs_root: root of the sysfs tree (for the FTDI latency timer).

    Returns:
        One ``PortInfo`` per port; empty when there is none.
    """
    from serial.tools import list_ports as serial_list_ports

    records = list(serial_list_ports.comports())
    logger.debug("comports() found %d port(s)", len(records))
    return describe_ports(records, sysfs_root=sysfs_root)
