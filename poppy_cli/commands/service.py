"""`poppy service`: the robot as an appliance: `poppy serve` started at boot by systemd
(install, status, logs, restart, stop, uninstall), and the served robot's motors released for
another program or taken back (release, take)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, NoReturn

import typer

from poppy_cli.options import JsonOpt
from poppy_cli.output import EXIT_USAGE, console, err_console, error_line, print_json

app = typer.Typer(
    help="Serve the robot at boot (a systemd service): install it, see it, stop it; release "
    "its motors for another program and take them back.",
    no_args_is_help=True,
)

DEFAULT_REMOTE = "http://127.0.0.1:8080"
FILE_MODE = 0o644
"""The units and the polkit rule: root (or the user) writes them, everyone reads them."""
SHOWN = ("Id", "LoadState", "ActiveState", "SubState", "UnitFileState", "MainPID", "FragmentPath")

UserOpt = typer.Option(
    False, "--user", help="The service of your own session (a desktop) instead of the system's."
)
RemoteOpt = typer.Option(
    DEFAULT_REMOTE,
    "--remote",
    help="The served robot (its token from POPPY_TOKEN).",
)


def _usage(message: str) -> NoReturn:
    error_line(message)
    raise typer.Exit(EXIT_USAGE)


@app.command("install")
def install(
    profile: str = typer.Option("ergo-jr", "--profile", help="The robot's profile."),
    port: str = typer.Option(
        "auto", "--port", "-p", help="Its serial port (auto: searched; /dev/ttyAMA0 on a Pi)."
    ),
    name: str = typer.Option(
        "poppy", "--name", "-n", help="The robot's name: its page is http://NAME.local."
    ),
    snap: bool = typer.Option(False, "--snap", help="Also serve Snap! with the Poppy blocks."),
    zmq: bool = typer.Option(False, "--zmq", help="Also serve pypot's ZMQ API (it has no token)."),
    token: bool = typer.Option(
        False,
        "--require-token",
        help="Require a token: a random one in a file only the service's user reads (kept on "
        "reinstall); the page's settings change it.",
    ),
    jupyter: bool = typer.Option(
        False, "--jupyter", help="Also start Jupyter (poppy-jupyter.service) on port 8888."
    ),
    user: bool = UserOpt,
    run_as: str | None = typer.Option(
        None,
        "--run-as",
        help="The user the system service runs as (default: who ran sudo; never root).",
    ),
    host: str = typer.Option("0.0.0.0", "--host", help="Address the page is served on."),
    http_ports: list[int] | None = typer.Option(
        None,
        "--http-port",
        min=0,
        max=65535,
        help="Ports of the page (default: 80 and 8080; 8080 with --user); repeat it.",
    ),
    dry_run: bool = typer.Option(
        False, "--dry-run", help="Print the units and the commands, change nothing."
    ),
) -> None:
    """Write poppy.service (and poppy-jupyter.service), reload systemd, enable and start it."""
    from poppy_cli import service_unit as units
    from poppy_cli.service_files import files_of, write_files
    from poppy_cli.service_polkit import RULE_FILE, polkit_dir, rule_text
    from poppy_cli.systemd import Systemd, unit_dir
    from poppy_core.assembly.serve_checks import LOOPBACK_HOSTS
    from poppy_core.checks import one_line, robot_name
    from poppy_core.errors import ArgumentError
    from poppy_core.files import write_file
    from poppy_core.robot import load_profile
    from poppy_core.server.serve_options import ServeOptions

    try:
        name = robot_name(name, "--name")  # the rule `poppy serve --name` applies
        for flag, value in (("--port", port), ("--host", host), ("--profile", profile)):
            one_line(value, flag)  # a newline would end the unit's ExecStart= line
    except ArgumentError as exc:
        _usage(str(exc))
    if not port.strip():
        _usage("--port is empty: give the serial port (e.g. /dev/ttyAMA0) or auto")
    if user and run_as is not None:
        _usage("--run-as is for the system service: a --user service runs as you")
    if zmq and token and host.strip("[]") not in LOOPBACK_HOSTS:
        _usage(
            f"--zmq with --require-token on {host}: pypot's ZMQ API has no token, anyone on the "
            "network could move the robot; drop --zmq (the REST API and Zenoh ask for the "
            "token), or serve on --host 127.0.0.1"
        )
    load_profile(profile)  # an unknown profile: one line naming the known ones
    ports = tuple(http_ports or (units.USER_PORTS if user else units.SYSTEM_PORTS))
    run_as = None if user else _service_user(run_as, dry_run)
    files = files_of(run_as)
    spec = units.ServiceSpec(
        poppy=units.poppy_command(),
        profile=profile,
        port=port,
        name=name,
        user=user,
        run_as=run_as,
        host=host,
        http_ports=ports,
        snap=snap,
        zmq=zmq,
        jupyter=jupyter,
        settings_file=files.settings,
        token_file=files.token if token else None,
    )
    try:
        texts = units.units(spec)
    except ArgumentError as exc:
        _usage(str(exc))
    systemd = Systemd(user)
    folder = unit_dir(user)
    stale = [] if jupyter else [units.JUPYTER_UNIT]
    if dry_run:
        for unit, text in texts.items():
            if len(texts) > 1:
                print(f"# {folder / unit}")
            print(text)
        scope = "--user " if user else ""
        written = [str(folder / u) for u in texts] + [str(files.settings)]
        if run_as is not None:
            written.append(str(polkit_dir() / RULE_FILE))
        if token:
            written.append(f"{files.token} (a random token, unless it holds one)")
        err_console.print(
            f"would write {', '.join(written)} and run: systemctl "
            f"{scope}daemon-reload; systemctl {scope}enable {' '.join(texts)}; systemctl "
            f"{scope}restart {' '.join(texts)}",
            soft_wrap=True,
            highlight=False,
            markup=False,
        )
        return
    systemd.systemctl("--version")  # no systemd: one line before anything is written
    # folders made on the way get at most rwxr-xr-x, whatever the umask (files: their modes)
    os.umask(os.umask(0o022) | 0o022)
    made = write_files(files, ServeOptions(snap=snap, zmq=zmq), token, run_as)
    _write_units(folder, texts)
    if run_as is not None:  # the page's restarts and settings, for the service's user
        write_file(
            polkit_dir() / RULE_FILE,
            rule_text(run_as, (units.UNIT, units.JUPYTER_UNIT)),
            replace=True,
            make_folder=True,
            mode=FILE_MODE,
        )
    _remove_units(systemd, folder, [u for u in stale if (folder / u).exists()])
    systemd.systemctl("daemon-reload")
    systemd.systemctl("enable", *texts)
    systemd.systemctl("restart", *texts)  # started, or restarted with the units just written
    where = f"http://{name}.local" + ("" if ports[0] == 80 else f":{ports[0]}")
    console.print(
        f"installed and started {', '.join(texts)} ({systemd.scope}): the page is at {where}; "
        f"`poppy service status{' --user' if user else ''}` shows it",
        soft_wrap=True,
        highlight=False,
        markup=False,
    )
    if made is not None:
        console.print(
            f"the robot's token (the page asks for it once): {made}; it is kept in "
            f"{files.token}, readable by the service's user only",
            soft_wrap=True,
            highlight=False,
            markup=False,
        )


def _service_user(run_as: str | None, dry_run: bool) -> str:
    """The user a system service runs as: ``--run-as``, else who ran sudo, else the current
    user; never root (a dry run shows root's unit, with a warning), and one that exists with
    a home (the service's settings and token are kept there)."""
    import getpass
    import os
    import pwd

    chosen = run_as or os.environ.get("SUDO_USER") or getpass.getuser()
    if chosen == "root":
        advice = "pass --run-as USER (a user of the dialout group, e.g. pi or poppy)"
        if not dry_run:
            _usage(f"the service must not run as root: {advice}")
        err_console.print(
            f"warning: this unit runs as root, which `poppy service install` refuses: {advice}",
            soft_wrap=True,
            highlight=False,
            markup=False,
        )
    try:
        home = Path(pwd.getpwnam(chosen).pw_dir)
    except KeyError:
        _usage(
            f"--run-as {chosen!r}: no such user on this machine; create it (sudo adduser "
            f"{chosen} && sudo adduser {chosen} dialout) or give another"
        )
    if not home.is_dir():
        _usage(
            f"--run-as {chosen!r}: its home {home} is not a folder, and the service keeps its "
            f"settings and token there; give a user with a home (sudo adduser poppy && sudo "
            "adduser poppy dialout)"
        )
    return chosen


def _write_units(folder: Path, texts: dict[str, str]) -> None:
    from poppy_core.files import write_file

    for unit, text in texts.items():
        write_file(folder / unit, text, replace=True, make_folder=True, mode=FILE_MODE)


def _installed(user: bool) -> list[str]:
    """The units of poppy installed (poppy.service first)."""
    from poppy_cli.service_unit import JUPYTER_UNIT, UNIT
    from poppy_cli.systemd import unit_dir

    folder = unit_dir(user)
    return [u for u in (UNIT, JUPYTER_UNIT) if (folder / u).exists()]


def _remove_units(systemd: Any, folder: Path, names: list[str]) -> None:
    if not names:
        return
    systemd.systemctl("disable", "--now", *names, check=False)
    for unit in names:
        try:
            (folder / unit).unlink()
        except FileNotFoundError:
            pass
        except OSError as exc:
            from poppy_core.files import file_error

            raise file_error(exc, folder / unit, "remove") from None


def _need_installed(user: bool) -> list[str]:
    names = _installed(user)
    if not names:
        scope = " --user" if user else ""
        error_line(
            f"poppy.service is not installed{' for this user' if user else ''}: "
            f"`poppy service install{scope}` installs it"
        )
        raise typer.Exit(1)
    return names


@app.command("status")
def status(user: bool = UserOpt, json_output: bool = JsonOpt) -> None:
    """Whether the service is installed, enabled and running (systemctl show)."""
    from poppy_cli.service_unit import JUPYTER_UNIT, UNIT
    from poppy_cli.systemd import Systemd

    systemd = Systemd(user)
    shown = systemd.systemctl("show", UNIT, JUPYTER_UNIT, f"--property={','.join(SHOWN)}")
    records = [_record(block, systemd.scope) for block in shown.split("\n\n") if block.strip()]
    if json_output:
        print_json(records)
        return
    from rich.table import Table

    table = Table(title=f"poppy's services ({systemd.scope})")
    for column in ("unit", "installed", "enabled", "state", "pid"):
        table.add_column(column)
    for record in records:
        running = record["active"] == "active"
        table.add_row(
            record["unit"],
            "yes" if record["installed"] else "no",
            record["enabled"] or "-",
            f"[{'green' if running else 'yellow'}]{record['active']} ({record['sub']})[/]",
            str(record["pid"] or "-"),
        )
    console.print(table)


def _record(block: str, scope: str) -> dict[str, Any]:
    values = dict(line.split("=", 1) for line in block.splitlines() if "=" in line)
    pid = int(values.get("MainPID", "0") or 0)
    return {
        "unit": values.get("Id", ""),
        "scope": scope,
        "installed": values.get("LoadState") == "loaded",
        "enabled": values.get("UnitFileState") or None,
        "active": values.get("ActiveState", "unknown"),
        "sub": values.get("SubState", "unknown"),
        "pid": pid or None,
        "path": values.get("FragmentPath") or None,
    }


@app.command("logs")
def logs(
    user: bool = UserOpt,
    lines: int = typer.Option(50, "--lines", min=1, max=100_000, help="Last lines shown."),
    follow: bool = typer.Option(False, "--follow", help="Keep showing new lines (Ctrl-C ends)."),
) -> None:
    """The service's log (journalctl): what `poppy serve` printed, warnings of lost motors..."""
    from poppy_cli.service_unit import UNIT
    from poppy_cli.systemd import Systemd

    code = Systemd(user).journal(UNIT, lines, follow)
    if code:
        raise typer.Exit(code)


@app.command("restart")
def restart(user: bool = UserOpt) -> None:
    """Restart the service (and Jupyter's), e.g. after `poppy snap download` or an update."""
    from poppy_cli.systemd import Systemd

    names = _need_installed(user)
    Systemd(user).systemctl("restart", *names)
    console.print(f"restarted {', '.join(names)}", highlight=False, markup=False)


@app.command("stop")
def stop(user: bool = UserOpt) -> None:
    """Stop the service until the next boot (`poppy service restart` starts it again)."""
    from poppy_cli.systemd import Systemd

    names = _need_installed(user)
    Systemd(user).systemctl("stop", *reversed(names))
    console.print(f"stopped {', '.join(names)}", highlight=False, markup=False)


@app.command("uninstall")
def uninstall(user: bool = UserOpt) -> None:
    """Stop and disable the service, remove its units, reload systemd."""
    from poppy_cli.systemd import Systemd, unit_dir

    systemd = Systemd(user)
    names = _installed(user)
    if not names:
        console.print("poppy.service is not installed: nothing to remove", highlight=False)
        return
    systemd.systemctl("--version")
    _remove_units(systemd, unit_dir(user), list(reversed(names)))
    if not user:
        from poppy_cli.service_polkit import RULE_FILE, polkit_dir

        (polkit_dir() / RULE_FILE).unlink(missing_ok=True)
    systemd.systemctl("daemon-reload")
    console.print(f"removed {', '.join(names)}", highlight=False, markup=False)


@app.command("release")
def release(remote: str = RemoteOpt, json_output: bool = JsonOpt) -> None:
    """Release the served robot's motors: all stopped, compliant, its ports closed for others.

    Another program (a notebook, `poppy scan`) can then open the ports; `poppy service take`
    takes them back."""
    done = _post(remote, "/api/v1/motors/release")
    if json_output:
        print_json(done)
        return
    stopped = [*done["primitives"], *done["moves"]]
    console.print(
        f"motors released: {', '.join(done['ports']) or 'no port'} free for another program"
        + (f" (stopped: {', '.join(stopped)})" if stopped else "")
        + "; `poppy service take` takes them back",
        soft_wrap=True,
        highlight=False,
        markup=False,
    )


@app.command("take")
def take(remote: str = RemoteOpt, json_output: bool = JsonOpt) -> None:
    """Take the served robot's motors back: its ports reopened (the motors stay compliant)."""
    done = _post(remote, "/api/v1/motors/take")
    if json_output:
        print_json(done)
        return
    console.print(
        f"motors taken back: {', '.join(done['ports']) or 'no port'} open",
        soft_wrap=True,
        highlight=False,
        markup=False,
    )
    for bus in done["no_motors"]:
        err_console.print(bus["message"], highlight=False, markup=False)


def _post(remote: str, path: str) -> dict[str, Any]:
    import os

    from poppy_core.remote.client import HttpClient

    client = HttpClient(remote, token=os.environ.get("POPPY_TOKEN") or None)
    try:
        answer: dict[str, Any] = client.request("POST", path, {})
    finally:
        client.close()
    return answer
