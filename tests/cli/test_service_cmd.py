"""`poppy service`: the units it writes, and the exact systemctl/journalctl commands it runs, seen
by a recording fake put first on PATH (issue 26.1). Release/take are tested on a served robot."""

from __future__ import annotations

import json
import os
import shlex
import shutil
import signal
import stat
import subprocess
from pathlib import Path

import httpx
import pytest

from poppy_core.emulator import serve_pty
from poppy_core.robot import load_profile
from poppy_core.robot.factory import virtual_buses
from tests.helpers.cli import Result, command_env, run_poppy
from tests.helpers.processes import reap, served_urls
from tests.helpers.recording import RecordingFake
from tests.helpers.waiting import eventually, http_timeout

SHOW = (
    "Id=poppy.service\nLoadState=loaded\nActiveState=active\nSubState=running\n"
    "UnitFileState=enabled\nMainPID=4242\nFragmentPath=/etc/systemd/system/poppy.service\n\n"
    "Id=poppy-jupyter.service\nLoadState=not-found\nActiveState=inactive\nSubState=dead\n"
    "UnitFileState=\nMainPID=0\nFragmentPath=\n"
)


class Fake(RecordingFake):
    """The recording systemctl/journalctl, and the unit folder."""

    def __init__(self, root: Path) -> None:
        super().__init__(root)
        self.units = root / "units"
        self.files = root / "service"
        self.polkit = root / "polkit"

    def env(self, **more: str) -> dict[str, str]:
        return super().env(
            POPPY_UNIT_DIR=str(self.units),
            POPPY_SERVICE_DIR=str(self.files),
            POPPY_POLKIT_DIR=str(self.polkit),
            **more,
        )

    def run(self, *args: str, **env: str) -> Result:
        return run_poppy("service", *args, env=self.env(**env))


@pytest.fixture
def fake(tmp_path: Path) -> Fake:
    return Fake(tmp_path)


@pytest.fixture
def someone() -> str:
    """A user of this machine that is not root, for --run-as."""
    import pwd

    users = [u.pw_name for u in pwd.getpwall() if u.pw_uid != 0 and Path(u.pw_dir).is_dir()]
    if not users:
        pytest.skip("no user but root on this machine")
    return users[0]


def exec_start(unit: str) -> list[str]:
    (line,) = [x for x in unit.splitlines() if x.startswith("ExecStart=")]
    return shlex.split(line.removeprefix("ExecStart="))


def test_the_user_unit_is_one_systemd_accepts(tmp_path: Path) -> None:
    if shutil.which("systemd-analyze") is None:
        pytest.skip("systemd-analyze is not installed (.ci/run installs Debian's systemd)")
    result = run_poppy("service", "install", "--user", "--dry-run", "--require-token")
    assert result.code == 0, result.stderr
    unit = tmp_path / "poppy.service"
    unit.write_text(result.stdout)
    verified = subprocess.run(
        ["systemd-analyze", "verify", str(unit)], capture_output=True, text=True, timeout=120
    )
    assert verified.returncode == 0, verified.stderr
    args = exec_start(result.stdout)
    assert Path(args[0]).is_absolute() and Path(args[0]).name == "poppy"
    expected = "serve --http --host 0.0.0.0 --http-port 8080 --profile ergo-jr --port auto"
    assert args[1:-4] == [*expected.split(), "--wait-for-motors", "--name", "poppy", "--announce"]
    assert args[-4] == "--settings" and args[-2] == "--token-file"  # the token not in the unit
    assert Path(args[-3]).name == "serve.json" and Path(args[-1]).name == "token"
    assert "Restart=on-failure" in result.stdout and "WantedBy=default.target" in result.stdout
    assert "AmbientCapabilities" not in result.stdout  # a user's manager cannot grant it
    assert (
        "would write" in result.stderr
        and "enable poppy.service; systemctl --user restart" in result.stderr
    )


def test_the_system_unit_serves_port_80_without_root(someone: str) -> None:
    result = run_poppy("service", "install", "--dry-run", "--run-as", someone, "--snap")
    assert result.code == 0, result.stderr
    unit = result.stdout
    args = exec_start(unit)
    assert args[args.index("--http-port") + 1] == "80" and args.count("--http-port") == 2
    assert "8080" in args and "--snap" not in args and args[-2] == "--settings"
    for line in (
        "AmbientCapabilities=CAP_NET_BIND_SERVICE",
        f"User={someone}",
        "Group=dialout",
        "Restart=on-failure",
        "WantedBy=multi-user.target",
    ):
        assert line in unit.splitlines(), line


def test_install_writes_the_units_then_reloads_enables_and_starts(fake: Fake, someone: str) -> None:
    result = fake.run("install", "--run-as", someone, "--port", "/dev/ttyAMA0", "--jupyter")
    assert result.code == 0, result.stderr
    assert fake.calls() == [
        ["systemctl", "--version"],
        ["systemctl", "daemon-reload"],
        ["systemctl", "enable", "poppy.service", "poppy-jupyter.service"],
        ["systemctl", "restart", "poppy.service", "poppy-jupyter.service"],
    ]
    serve = exec_start((fake.units / "poppy.service").read_text())
    assert serve[serve.index("--port") + 1] == "/dev/ttyAMA0"
    jupyter = exec_start((fake.units / "poppy-jupyter.service").read_text())
    expected = "notebook --host 0.0.0.0 --port 8888 --robot http://127.0.0.1:8080 --no-browser"
    assert jupyter[1:] == expected.split()
    assert "http://poppy.local" in result.stdout

    fake.forget()  # installed again without Jupyter: its unit goes
    assert fake.run("install", "--run-as", someone).code == 0
    assert fake.calls() == [
        ["systemctl", "--version"],
        ["systemctl", "disable", "--now", "poppy-jupyter.service"],
        ["systemctl", "daemon-reload"],
        ["systemctl", "enable", "poppy.service"],
        ["systemctl", "restart", "poppy.service"],
    ]
    assert sorted(p.name for p in fake.units.iterdir()) == ["poppy.service"]


def test_install_writes_the_settings_file_and_a_token_only_its_user_reads(
    fake: Fake, someone: str
) -> None:
    result = fake.run("install", "--run-as", someone, "--snap", "--require-token")
    assert result.code == 0, result.stderr
    settings, token = fake.files / "serve.json", fake.files / "token"
    assert json.loads(settings.read_text()) == {"snap": True, "zmq": False}
    assert stat.S_IMODE(token.stat().st_mode) == 0o600
    secret = token.read_text().strip()
    assert len(secret) >= 16 and secret in result.stdout  # told once, at install
    unit = (fake.units / "poppy.service").read_text()
    assert secret not in unit
    args = exec_start(unit)
    assert args[-4:] == ["--settings", str(settings), "--token-file", str(token)]

    # installed again: the options as its flags say, the token (maybe changed by the page) kept
    token.write_text("set-from-the-page\n")
    # (ZMQ beside a token only on loopback: it has no token of its own)
    again = fake.run(
        "install", "--run-as", someone, "--zmq", "--require-token", "--host", "127.0.0.1"
    )
    assert again.code == 0, again.stderr
    assert json.loads(settings.read_text()) == {"snap": False, "zmq": True}
    assert token.read_text() == "set-from-the-page\n" and "token" not in again.stdout
    assert "--token-file" in exec_start((fake.units / "poppy.service").read_text())
    assert fake.run("install", "--run-as", someone).code == 0  # no --require-token: none
    assert "--token-file" not in exec_start((fake.units / "poppy.service").read_text())


def test_a_user_install_drives_the_user_manager(fake: Fake) -> None:
    result = fake.run("install", "--user", "--name", "ergo-2")
    assert result.code == 0, result.stderr
    assert fake.calls() == [
        ["systemctl", "--user", "--version"],
        ["systemctl", "--user", "daemon-reload"],
        ["systemctl", "--user", "enable", "poppy.service"],
        ["systemctl", "--user", "restart", "poppy.service"],
    ]
    assert "http://ergo-2.local:8080" in result.stdout


def test_status_logs_restart_stop_uninstall(fake: Fake, someone: str) -> None:
    assert fake.run("install", "--run-as", someone, "--jupyter").code == 0
    fake.forget()
    status = fake.run("status", "--json", FAKE_COMMANDS_SHOW=SHOW)
    assert status.code == 0, status.stderr
    assert status.json() == [
        {
            "unit": "poppy.service",
            "scope": "system",
            "installed": True,
            "enabled": "enabled",
            "active": "active",
            "sub": "running",
            "pid": 4242,
            "path": "/etc/systemd/system/poppy.service",
        },
        {
            "unit": "poppy-jupyter.service",
            "scope": "system",
            "installed": False,
            "enabled": None,
            "active": "inactive",
            "sub": "dead",
            "pid": None,
            "path": None,
        },
    ]
    table = fake.run("status", FAKE_COMMANDS_SHOW=SHOW)
    assert table.code == 0 and "poppy.service" in table.stdout and "running" in table.stdout
    assert fake.run("logs").code == 0
    assert fake.run("logs", "--user", "--lines", "200", "--follow").code == 0
    assert fake.run("restart").code == 0
    assert fake.run("stop").code == 0
    assert fake.run("uninstall").code == 0
    properties = "--property=Id,LoadState,ActiveState,SubState,UnitFileState,MainPID,FragmentPath"
    assert fake.calls() == [
        ["systemctl", "show", "poppy.service", "poppy-jupyter.service", properties],
        ["systemctl", "show", "poppy.service", "poppy-jupyter.service", properties],
        ["journalctl", "--unit", "poppy.service", "--lines", "50", "--no-pager"],
        ["journalctl", "--user-unit", "poppy.service", "--lines", "200", "--no-pager", "--follow"],
        ["systemctl", "restart", "poppy.service", "poppy-jupyter.service"],
        ["systemctl", "stop", "poppy-jupyter.service", "poppy.service"],
        ["systemctl", "--version"],
        ["systemctl", "disable", "--now", "poppy-jupyter.service", "poppy.service"],
        ["systemctl", "daemon-reload"],
    ]
    assert list(fake.units.iterdir()) == []


def test_what_is_not_installed_says_how_to_install_it(fake: Fake) -> None:
    for command in ("restart", "stop"):
        result = fake.run(command, "--user")
        assert result.code == 1
        assert "poppy.service is not installed" in result.stderr
        assert "`poppy service install --user`" in result.stderr
    assert fake.run("uninstall").code == 0
    assert fake.calls() == []


def test_a_failing_systemctl_is_one_line(fake: Fake, someone: str) -> None:
    result = fake.run("install", "--run-as", someone, FAKE_COMMANDS_EXIT="1")
    assert result.code == 1
    assert result.stderr.count("\n") == 1 and "`systemctl --version` failed" in result.stderr
    assert not fake.units.exists()  # nothing written


@pytest.mark.parametrize(
    ("args", "says", "code"),
    [
        (("--name", "Poppy_1"), "--name 'Poppy_1' is not a robot name", 2),
        (("--name", "-poppy"), "is not a robot name", 2),
        (("--port", " "), "--port is empty", 2),
        (("--run-as", "root"), "must not run as root: pass --run-as USER", 2),
        (("--run-as", "no-such-user-here"), "no such user on this machine", 2),
        (("--user", "--run-as", "pi"), "--run-as is for the system service", 2),
        (("--profile", "no-such-robot"), "no-such-robot", 1),
        (("--http-port", "70000"), "'--http-port': Input should be less than or equal to 65535", 2),
        (("--zmq", "--require-token"), "--zmq with --require-token on 0.0.0.0", 2),
        (("--zmq", "--require-token", "--dry-run"), "pypot's ZMQ API has no token", 2),
    ],
)
def test_bad_install_options_are_one_line(
    fake: Fake, args: tuple[str, ...], says: str, code: int
) -> None:
    result = fake.run("install", *args)
    assert result.code == code, result.stderr
    assert says in result.stderr and "Traceback" not in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1, result.stderr
    assert fake.calls() == [] and not fake.units.exists()


def test_the_dry_run_as_root_shows_root_s_unit_with_a_warning(fake: Fake) -> None:
    result = fake.run("install", "--dry-run", "--run-as", "root")
    assert result.code == 0, result.stderr
    assert "User=root" in result.stdout
    (warning,) = result.stderr.strip().splitlines()[:-1]  # then what it would write
    assert warning.startswith("warning: this unit runs as root") and "--run-as USER" in warning
    assert fake.calls() == [] and not fake.units.exists()


def test_a_user_without_a_home_is_refused(fake: Fake) -> None:
    import pwd

    homeless = [u.pw_name for u in pwd.getpwall() if not Path(u.pw_dir).is_dir()]
    if not homeless:
        pytest.skip("every user of this machine has a home")
    for args in ((), ("--dry-run",)):
        result = fake.run("install", "--run-as", homeless[0], *args)
        assert result.code == 2, result.stderr
        assert "is not a folder" in result.stderr and "Traceback" not in result.stderr
        assert len(result.stderr.strip().splitlines()) == 1, result.stderr
        assert fake.calls() == [] and not fake.units.exists() and "/" not in result.stdout


def test_without_systemd_install_is_one_line_and_writes_nothing(
    fake: Fake, someone: str, tmp_path: Path
) -> None:
    empty = tmp_path / "empty"
    empty.mkdir()
    result = run_poppy(
        "service", "install", "--run-as", someone, env={**fake.env(), "PATH": str(empty)}
    )
    assert result.code == 1
    assert "systemctl not found: this machine does not run systemd" in result.stderr
    assert not fake.units.exists()


def test_the_units_exec_start_run_as_is_serves_the_page(tmp_path: Path) -> None:
    # needs `poppy serve --name/--announce` (issue 26 item 2, branch s26-net)
    (virtual,) = virtual_buses(load_profile("ergo-jr")).values()
    port = str(tmp_path / "ttyDXL")
    install = ("install", "--user", "--dry-run", "--host", "127.0.0.1", "--port", port)
    result = run_poppy(
        "service",
        *install,
        "--http-port",
        "0",
        "--http-port",
        "0",
        env={"POPPY_SERVICE_DIR": str(tmp_path / "service")},  # none: Snap! and ZMQ off
    )
    assert result.code == 0, result.stderr
    env = dict(os.environ, **command_env({"POPPY_MOVES_DIR": str(tmp_path / "moves")}))
    with serve_pty(virtual, link=port):
        proc = subprocess.Popen(
            exec_start(result.stdout),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        try:
            assert proc.stdout is not None
            urls = served_urls(proc.stdout)
            assert len(urls) == 2, proc.stderr.read() if proc.stderr else ""
            for url in urls:
                page = httpx.get(url + "/", timeout=http_timeout(30))
                assert page.status_code == 200 and "Release the motors" in page.text
            motors_url = urls[1] + "/api/v1/motors"

            def all_online() -> bool:
                motors = httpx.get(motors_url, timeout=http_timeout(30)).json()
                return bool(motors) and all(m["online"] for m in motors)

            # a motor a loaded machine made miss its replies is back online at the next retry
            assert eventually(all_online, timeout_s=30)
            released = run_poppy("service", "release", "--remote", urls[1], "--json")
            assert released.code == 0, released.stderr
            assert released.json()["ports"] == [port] and released.json()["released"] is True
            taken = run_poppy("service", "take", "--remote", urls[0])
            assert taken.code == 0, taken.stderr
            assert f"motors taken back: {port} open" in taken.stdout
        finally:
            proc.send_signal(signal.SIGTERM)
            assert proc.wait(timeout=30) == 0
            reap(proc)


def test_release_of_a_robot_not_served_is_one_line() -> None:
    result = run_poppy("service", "release", "--remote", "http://127.0.0.1:9")
    assert result.code == 1 and "cannot reach http://127.0.0.1:9" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    bad = run_poppy("service", "take", "--remote", "ftp://robot")
    assert bad.code == 1 and "is not an http://host:port URL" in bad.stderr


def test_is_active_asks_systemctl(fake: Fake, monkeypatch: pytest.MonkeyPatch) -> None:
    from poppy_cli.systemd import Systemd

    for name, value in fake.env().items():
        monkeypatch.setenv(name, value)
    assert Systemd(user=True).is_active("poppy.service")
    monkeypatch.setenv("FAKE_COMMANDS_EXIT", "3")  # systemctl's answer for inactive
    assert not Systemd(user=False).is_active("poppy.service")
    assert fake.calls() == [
        ["systemctl", "--user", "is-active", "--quiet", "poppy.service"],
        ["systemctl", "is-active", "--quiet", "poppy.service"],
    ]


def test_the_installed_service_reads_its_token_and_options_from_its_files(
    fake: Fake, tmp_path: Path
) -> None:
    (virtual,) = virtual_buses(load_profile("ergo-jr")).values()
    port = str(tmp_path / "ttyDXL")
    install = ("install", "--user", "--require-token", "--host", "127.0.0.1", "--port", port)
    assert fake.run(*install, "--http-port", "0").code == 0
    token = (fake.files / "token").read_text().strip()
    env = dict(os.environ, **command_env({"POPPY_MOVES_DIR": str(tmp_path / "moves")}))
    env.pop("POPPY_TOKEN", None)
    with serve_pty(virtual, link=port):
        proc = subprocess.Popen(
            exec_start((fake.units / "poppy.service").read_text()),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        try:
            assert proc.stdout is not None
            url = next(line.strip() for line in proc.stdout if line.startswith("http://"))
            assert httpx.get(url + "/api/v1/motors", timeout=http_timeout(30)).status_code == 401
            bearer = {"Authorization": f"Bearer {token}"}
            shown = httpx.get(
                url + "/api/v1/settings", headers=bearer, timeout=http_timeout(30)
            ).json()
            assert shown["token_required"] and shown["token_changeable"]
            assert shown["services"]["snap"] == {"on": False, "unit": None, "how": "settings"}
            assert shown["restarts"] is False  # run by hand, not by systemd
        finally:
            proc.send_signal(signal.SIGTERM)
            assert proc.wait(timeout=30) == 0
            reap(proc)


@pytest.mark.parametrize(
    ("args", "says", "code"),
    [
        (("--settings", "s.json", "--snap"), "leave --snap and --zmq out", 2),
        (("--token-file", "t", "--token", "x" * 16), "not both", 2),
        (("--token-file", "missing-token"), "missing-token does not exist", 1),
        (("--settings", "bad.json"), "is not JSON", 1),
    ],
)
def test_serve_s_files_refused_in_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, args: tuple[str, ...], says: str, code: int
) -> None:
    (tmp_path / "bad.json").write_text("{")
    monkeypatch.delenv("POPPY_TOKEN", raising=False)
    given = [a if a.startswith(("-", "x")) else str(tmp_path / a) for a in args]
    result = run_poppy("serve", "--http", "--sim", "--profile", "ergo-jr", *given)
    assert result.code == code, result.stderr
    assert says in result.stderr and "Traceback" not in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1, result.stderr


def test_a_system_install_lets_its_user_restart_its_units_and_nothing_more(
    fake: Fake, someone: str
) -> None:
    # The page's settings restart poppy.service and change the name and Wi-Fi as the service's
    # user: a polkit rule allows exactly that, and goes with the service.
    assert fake.run("install", "--run-as", someone).code == 0
    rule = (fake.polkit / "50-poppy.rules").read_text()
    assert f'subject.user != "{someone}"' in rule
    assert '["poppy.service", "poppy-jupyter.service"]' in rule
    assert '["start", "stop", "restart"]' in rule
    assert "org.freedesktop.hostname1.set-static-hostname" in rule
    assert "org.freedesktop.NetworkManager.settings.modify.system" in rule
    assert "polkit.Result.YES" in rule and '"enable"' not in rule  # never enable other units
    assert fake.run("uninstall").code == 0
    assert not (fake.polkit / "50-poppy.rules").exists()
    assert fake.run("install", "--user").code == 0  # a user's manager needs no rule
    assert not (fake.polkit / "50-poppy.rules").exists()


def test_the_polkit_rule_answers_as_polkit_would_ask(tmp_path: Path) -> None:
    # polkit runs the rule as JavaScript: Node.js stands in for its interpreter, with a
    # polkit object that records the rule and actions that answer lookup("unit"/"verb").
    import shutil
    import subprocess

    from poppy_cli.service_polkit import rule_text

    node = shutil.which("node")
    if node is None:
        pytest.skip("Node.js is not installed: the rule's JavaScript is not run")
    probe = tmp_path / "rule.js"
    probe.write_text(
        "var rules = [];\n"
        'var polkit = {Result: {YES: "yes", NOT_HANDLED: "no"}, '
        "addRule: function (f) { rules.push(f); }};\n"
        + rule_text("pi", ("poppy.service", "poppy-jupyter.service"))
        + "function ask(id, unit, verb, user) {\n"
        '  var action = {id: id, lookup: function (k) { return k == "unit" ? unit : verb; }};\n'
        "  return rules[0](action, {user: user});\n"
        "}\n"
        'var units = "org.freedesktop.systemd1.manage-units";\n'
        "console.log([\n"
        '  ask(units, "poppy.service", "restart", "pi"),\n'
        '  ask(units, "poppy-jupyter.service", "stop", "pi"),\n'
        '  ask(units, "ssh.service", "restart", "pi"),\n'
        '  ask(units, "poppy.service", "restart", "bob"),\n'
        '  ask("org.freedesktop.hostname1.set-static-hostname", "", "", "pi"),\n'
        '  ask("org.freedesktop.login1.reboot", "", "", "pi"),\n'
        '].join(" "));\n'
    )
    out = subprocess.run([node, str(probe)], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["yes", "yes", "no", "no", "yes", "no"]


def test_zmq_with_a_token_is_served_on_loopback_only(fake: Fake) -> None:
    result = fake.run(
        "install", "--user", "--dry-run", "--zmq", "--require-token", "--host", "127.0.0.1"
    )
    assert result.code == 0, result.stderr
    assert "--host 127.0.0.1" in result.stdout and "--token-file" in result.stdout
