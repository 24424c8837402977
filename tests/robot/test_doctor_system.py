"""`poppy doctor`'s checks of the machine, on fakes: camera, service, disk, the command runner."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from poppy_core.robot.config import RobotConfig
from poppy_core.robot.doctor import check_adapter, check_latency
from poppy_core.robot.doctor_system import (
    SystemProbe,
    check_camera,
    check_disk,
    check_service,
    run_command,
    service_scope,
)
from poppy_core.robot.profiles import load_profile


def _with_camera(index: int) -> RobotConfig:
    data = load_profile("ergo-jr").to_dict()
    data["sensors"]["camera"]["index"] = index
    return RobotConfig.from_dict(data)


def test_a_camera_at_any_index_is_any_video_device(tmp_path: Path) -> None:
    probe = SystemProbe(dev_root=str(tmp_path))
    (check,) = check_camera(_with_camera(-1), probe)
    assert check.status == "fail" and check.detail.endswith("video* not found")
    (tmp_path / "video2").write_text("")
    (check,) = check_camera(_with_camera(-1), probe)
    assert (check.status, check.detail) == ("pass", f"{tmp_path / 'video2'} present")


def test_the_service_is_looked_for_system_wide_then_for_the_user() -> None:
    asked: list[list[str]] = []

    def systemctl(argv: Sequence[str]) -> tuple[int, str]:
        asked.append(list(argv))
        if "--user" in argv:
            return (3, "failed") if "is-active" in argv else (0, "enabled")
        return 4, "not-found"

    probe = SystemProbe(run=systemctl)
    scope = service_scope(probe)
    assert scope == ["--user"]
    check, installed = check_service(probe, scope)
    assert installed and check.status == "fail"
    assert check.detail == "poppy.service is failed"
    assert check.fix is not None and check.fix.startswith("poppy service restart")
    assert asked[:2] == [
        ["systemctl", "is-enabled", "poppy.service"],
        ["systemctl", "--user", "is-enabled", "poppy.service"],
    ]


def test_no_systemd_means_no_service_installed() -> None:
    probe = SystemProbe(run=lambda argv: run_command(["/nonexistent/systemctl", *argv[1:]]))
    assert run_command(["/nonexistent/systemctl"])[0] == 127
    assert service_scope(probe) is None
    check, installed = check_service(probe, None)
    assert (check.status, installed) == ("skip", False)


def test_a_full_disk_fails_with_its_fix(tmp_path: Path) -> None:
    probe = SystemProbe(disk_path=tmp_path / "not" / "yet")
    assert check_disk(probe).status == "pass"
    check = check_disk(probe, min_free_mb=10**12)
    assert (
        check.status == "fail"
        and check.fix == "free some space: `poppy moves list`, `poppy moves rm NAME`"
    )


def test_the_adapter_must_be_there_and_readable(tmp_path: Path) -> None:
    assert check_adapter(None).status == "fail"
    assert check_adapter(str(tmp_path / "ttyUSB9")).detail.endswith("does not exist")
    device = tmp_path / "ttyUSB0"
    device.write_text("")
    denied = check_adapter(str(device), access=lambda path, mode: False)
    assert denied.status == "fail" and denied.fix is not None and "dialout" in denied.fix
    assert check_adapter(str(device)).status == "pass"
    assert check_latency(str(device), str(tmp_path)).status == "skip"
