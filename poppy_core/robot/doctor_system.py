"""`poppy doctor`'s checks of the machine (camera, service, page, disk) and the whole run.

What the machine is asked goes through :class:`SystemProbe` (sysfs and /dev roots, a command
runner for ``systemctl``, an HTTP fetch, the access check), so that tests point every check at
fakes and temporary files.
"""

from __future__ import annotations

import logging
import os
import re
import shutil
import subprocess
import urllib.error
import urllib.request
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from poppy_core.robot.config import RobotConfig
from poppy_core.robot.doctor import (
    Check,
    DoctorReport,
    check_adapter,
    check_latency,
    check_motors,
)

logger = logging.getLogger(__name__)

SERVICE = "poppy.service"
MIN_FREE_MB = 100
"""Free space wanted where moves are saved (a minute's recording is a few hundred kB)."""
# `systemctl is-enabled` answers these for a unit that exists (systemctl(1)).
_INSTALLED_STATES = {
    "enabled",
    "enabled-runtime",
    "linked",
    "linked-runtime",
    "alias",
    "masked",
    "masked-runtime",
    "static",
    "indirect",
    "disabled",
    "generated",
    "transient",
}
Runner = Callable[[Sequence[str]], tuple[int, str]]
Fetch = Callable[[str], int | None]


def run_command(argv: Sequence[str]) -> tuple[int, str]:
    """Run ``argv``; its exit code and output (127 and the reason when it cannot start)."""
    try:
        done = subprocess.run(list(argv), capture_output=True, text=True, timeout=10, check=False)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return 127, str(exc)
    return done.returncode, (done.stdout or done.stderr).strip()


def http_status(url: str) -> int | None:
    """The HTTP status of a GET of ``url``, None when nothing answers."""
    try:
        with urllib.request.urlopen(url, timeout=5) as response:
            return int(response.status)
    except urllib.error.HTTPError as exc:
        return exc.code
    except (OSError, ValueError):
        return None


@dataclass
class SystemProbe:
    """Where the doctor looks on this machine (tests give fakes).

    Attributes:
        sysfs_root: root of sysfs (the FTDI latency timer).
        dev_root: root of the device files (cameras: ``video0``...).
        run: runs a command, returns (exit code, output): ``systemctl``.
        fetch: GETs a URL, returns its HTTP status or None.
        access: ``os.access``-like check of the serial port.
        disk_path: a folder whose disk holds the moves.
    """

    sysfs_root: str = "/sys"
    dev_root: str = "/dev"
    run: Runner = run_command
    fetch: Fetch = http_status
    access: Callable[[str, int], bool] = os.access
    disk_path: Path = field(default_factory=Path.home)


def check_camera(config: RobotConfig, probe: SystemProbe) -> list[Check]:
    """Each camera of the profile has its device (``/dev/videoN``, or the path given)."""
    checks = []
    for sensor_name, sensor in config.sensors.items():
        name = "camera" if sensor_name == "camera" else f"camera {sensor_name}"
        if not sensor.type.lower().endswith("camera"):
            continue
        where = sensor.device if sensor.device is not None else sensor.index
        if isinstance(where, int) and where < 0:  # pypot's -1: any camera
            videos = sorted(Path(probe.dev_root).glob("video*"))
            path = str(videos[0]) if videos else os.path.join(probe.dev_root, "video*")
        elif where is None or isinstance(where, int):
            path = os.path.join(probe.dev_root, f"video{where or 0}")
        else:
            path = where
        if os.path.exists(path):
            checks.append(Check(name, "pass", f"{path} present"))
        else:
            checks.append(
                Check(
                    name,
                    "fail",
                    f"{path} not found",
                    "plug the camera (on a Pi: its ribbon, then sudo raspi-config to enable it); "
                    "`poppy camera list` shows what is seen",
                )
            )
    if not checks:
        checks.append(Check("camera", "skip", "the profile has no camera"))
    return checks


def service_scope(probe: SystemProbe) -> list[str] | None:
    """``[]`` for the system's poppy.service, ``["--user"]`` for the user's, None when neither
    is installed (or there is no systemd)."""
    for scope in ([], ["--user"]):
        code, out = probe.run(["systemctl", *scope, "is-enabled", SERVICE])
        if code != 127 and out.split()[:1] and out.split()[0] in _INSTALLED_STATES:
            return scope
    return None


def check_service(probe: SystemProbe, scope: list[str] | None) -> tuple[Check, bool]:
    """poppy.service (installed in ``scope``, see :func:`service_scope`) is running; also
    whether it is installed (the page is checked then)."""
    if scope is None:
        return (
            Check(
                "service",
                "skip",
                f"{SERVICE} is not installed (a robot's Pi runs it at boot)",
                "poppy service install --profile PROFILE",
            ),
            False,
        )
    code, out = probe.run(["systemctl", *scope, "is-active", SERVICE])
    state = out.split()[0] if out.split() else "unknown"
    label = " ".join(["systemctl", *scope]).strip()
    if code == 0 and state == "active":
        return Check("service", "pass", f"{SERVICE} active ({label})"), True
    return (
        Check(
            "service",
            "fail",
            f"{SERVICE} is {state}",
            f"poppy service restart (logs: poppy service logs, or {label} status {SERVICE})",
        ),
        True,
    )


_NAME_FLAG = re.compile(r"--name[= ]+([A-Za-z0-9][A-Za-z0-9-]*)")
DEFAULT_NAME = "poppy"


def service_name(probe: SystemProbe, scope: list[str] | None) -> str:
    """The robot's name the installed service gives `poppy serve` (``--name`` in its unit's
    ExecStart), else ``poppy``, the service's default."""
    if scope is None:
        return DEFAULT_NAME
    code, out = probe.run(["systemctl", *scope, "cat", SERVICE])
    found = _NAME_FLAG.search(out) if code == 0 else None
    return found.group(1) if found else DEFAULT_NAME


_PROFILE_FLAG = re.compile(r"^ExecStart=.*?--profile[= ]+([A-Za-z0-9][A-Za-z0-9_.-]*)", re.M)


def service_profile(probe: SystemProbe) -> str | None:
    """The profile the installed poppy.service serves (``--profile`` in its unit's ExecStart),
    None when it is not installed or names none."""
    scope = service_scope(probe)
    if scope is None:
        return None
    code, out = probe.run(["systemctl", *scope, "cat", SERVICE])
    found = _PROFILE_FLAG.search(out) if code == 0 else None
    return found.group(1) if found else None


def check_page(url: str, installed: bool, probe: SystemProbe) -> Check:
    """The robot's page answers at ``url`` (http://NAME.local/), when the service is installed."""
    if not installed:
        return Check("page", "skip", f"{SERVICE} is not installed: {url} not checked")
    status = probe.fetch(url)
    if status is not None and status < 400:
        return Check("page", "pass", f"{url} answers ({status})")
    seen = "nothing answers" if status is None else f"HTTP {status}"
    return Check(
        "page",
        "fail",
        f"{url}: {seen}",
        "poppy service status; the name needs mDNS: `poppy serve --name NAME --announce`",
    )


def check_disk(probe: SystemProbe, min_free_mb: int = MIN_FREE_MB) -> Check:
    """Room left for recorded moves on the disk of ``probe.disk_path``."""
    path = probe.disk_path
    while not path.exists() and path != path.parent:
        path = path.parent
    free_mb = shutil.disk_usage(path).free / 1e6
    if free_mb >= min_free_mb:
        return Check("disk", "pass", f"{free_mb:,.0f} MB free for moves ({probe.disk_path})")
    return Check(
        "disk",
        "fail",
        f"{free_mb:,.0f} MB free at {probe.disk_path} (want {min_free_mb} MB)",
        "free some space: `poppy moves list`, `poppy moves rm NAME`",
    )


def run_doctor(
    config: RobotConfig,
    profile: str,
    port: str | None,
    *,
    page_url: str | None = None,
    probe: SystemProbe | None = None,
    progress: Callable[[Check], None] | None = None,
) -> DoctorReport:
    """Run every check, in order: adapter, latency timer, motors, camera, service, page, disk.

    Args:
        config: the robot's profile.
        profile: its name (for the fix commands).
        port: the bus's port; None when no adapter was found.
        page_url: where the robot's page must answer when the service is installed (None:
            ``http://NAME.local/``, NAME as the installed service names the robot).
        probe: where to look on this machine (None: the real one).
        progress: called with each check as soon as it is done.
    """
    probe = probe or SystemProbe()
    report = DoctorReport()

    def add(*checks: Check) -> None:
        for check in checks:
            report.checks.append(check)
            if progress is not None:
                progress(check)

    adapter = check_adapter(port, probe.access)
    add(adapter)
    reachable = port if adapter.status == "pass" else None
    add(check_latency(reachable, probe.sysfs_root))
    add(*check_motors(config, profile, reachable))
    add(*check_camera(config, probe))
    scope = service_scope(probe)
    service, installed = check_service(probe, scope)
    add(service)
    url = page_url or f"http://{service_name(probe, scope)}.local/"
    add(check_page(url, installed, probe))
    add(check_disk(probe))
    return report
