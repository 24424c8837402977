"""The systemd units of `poppy service install`: `poppy.service` (the robot's page and API) and
`poppy-jupyter.service` (a Jupyter server whose notebooks reach that robot)."""

from __future__ import annotations

import os
import shlex
import shutil
import sys
from dataclasses import dataclass, field
from pathlib import Path

from poppy_core.checks import one_line

UNIT = "poppy.service"
JUPYTER_UNIT = "poppy-jupyter.service"
JUPYTER_PORT = 8888
SYSTEM_PORTS = (80, 8080)
"""The appliance serves its page on port 80 (``http://poppy.local``) and keeps pypot's 8080."""
USER_PORTS = (8080,)
"""A user's service cannot be given the capability to bind port 80: 8080 only."""


@dataclass(frozen=True)
class ServiceSpec:
    """What `poppy service install` was asked for.

    Attributes:
        poppy: the `poppy` command the units run (its absolute path, or Python's with
            ``-m poppy_cli``).
        profile: the robot's profile.
        port: its serial port (``auto``: searched for).
        name: the robot's name (``NAME.local``).
        user: a unit of the user's session instead of a system one.
        run_as: the user a system unit runs as (None for a user unit).
        host: the address the page is served on.
        http_ports: the page's ports (the first one, then its aliases).
        snap: serve Snap! too (the initial settings file).
        zmq: serve pypot's ZMQ API too (the initial settings file).
        jupyter: also write `poppy-jupyter.service`.
        settings_file: the serve options file the unit reads (``--settings``), or None.
        token_file: the token file the unit reads (``--token-file``), or None: no token.
    """

    poppy: tuple[str, ...]
    profile: str = "ergo-jr"
    port: str = "auto"
    name: str = "poppy"
    user: bool = False
    run_as: str | None = None
    host: str = "0.0.0.0"
    http_ports: tuple[int, ...] = field(default=SYSTEM_PORTS)
    snap: bool = False
    zmq: bool = False
    jupyter: bool = False
    settings_file: Path | None = None
    token_file: Path | None = None

    @property
    def robot_url(self) -> str:
        """Where the notebooks reach the robot: the page's last port (8080) on loopback."""
        return f"http://127.0.0.1:{self.http_ports[-1]}"


def poppy_command() -> tuple[str, ...]:
    """The absolute path of the `poppy` command installed beside this Python (a venv's), else the
    one on PATH, else ``python -m poppy_cli`` of this Python."""
    beside = Path(sys.executable).parent / "poppy"
    if beside.is_file() and os.access(beside, os.X_OK):
        return (str(beside.absolute()),)
    found = shutil.which("poppy")
    if found:
        return (str(Path(found).absolute()),)
    return (str(Path(sys.executable).absolute()), "-m", "poppy_cli")


def serve_command(spec: ServiceSpec) -> list[str]:
    """The `poppy serve` command line of `poppy.service` (ExecStart)."""
    args = [*spec.poppy, "serve", "--http", "--host", spec.host]
    for port in spec.http_ports:
        args += ["--http-port", str(port)]
    args += ["--profile", spec.profile, "--port", spec.port, "--wait-for-motors"]
    args += ["--name", spec.name, "--announce"]
    if spec.settings_file is not None:  # Snap! and ZMQ: as the file says, the page switches them
        args += ["--settings", str(spec.settings_file)]
    else:
        args += [flag for flag, on in (("--snap", spec.snap), ("--zmq", spec.zmq)) if on]
    if spec.token_file is not None:
        args += ["--token-file", str(spec.token_file)]
    return args


def jupyter_command(spec: ServiceSpec) -> list[str]:
    """The `poppy notebook` command line of `poppy-jupyter.service` (ExecStart)."""
    host = "127.0.0.1" if spec.user else "0.0.0.0"
    return [
        *spec.poppy,
        "notebook",
        "--host",
        host,
        "--port",
        str(JUPYTER_PORT),
        "--robot",
        spec.robot_url,
        "--no-browser",
    ]


def _exec(args: list[str]) -> str:
    # systemd's ExecStart splits words as a shell does, and expands % and $: quote both; a
    # newline would end the line (and start another, root's ExecStartPre= say): refused
    for arg in args:
        one_line(arg, "a word of ExecStart")
    line = " ".join(shlex.quote(a) for a in args)
    return line.replace("%", "%%").replace("$", "$$")


def serve_unit(spec: ServiceSpec) -> str:
    """The text of `poppy.service`."""
    lines = ["[Unit]", f"Description=poppy: the robot {spec.name}'s page and API"]
    if not spec.user:  # the user's manager has no network target
        lines += ["Wants=network-online.target", "After=network-online.target"]
    lines += [
        "",
        "[Service]",
        "Type=simple",
        f"ExecStart={_exec(serve_command(spec))}",
        "Environment=PYTHONUNBUFFERED=1",
        "Restart=on-failure",
        "RestartSec=5",
    ]
    if not spec.user:
        lines += [
            f"User={spec.run_as or 'poppy'}",
            "Group=dialout",
            "SupplementaryGroups=video",
            "# port 80 without root",
            "AmbientCapabilities=CAP_NET_BIND_SERVICE",
            "CapabilityBoundingSet=CAP_NET_BIND_SERVICE",
            "NoNewPrivileges=yes",
        ]
    lines += ["", "[Install]", f"WantedBy={_target(spec)}", ""]
    return "\n".join(lines)


def jupyter_unit(spec: ServiceSpec) -> str:
    """The text of `poppy-jupyter.service`."""
    lines = [
        "[Unit]",
        f"Description=poppy: Jupyter notebooks for the robot {spec.name}",
        f"Wants={UNIT}",
        f"After={UNIT}",
        "",
        "[Service]",
        "Type=simple",
        f"ExecStart={_exec(jupyter_command(spec))}",
        "Environment=PYTHONUNBUFFERED=1",
        "Restart=on-failure",
        "RestartSec=5",
    ]
    if not spec.user:
        lines += [f"User={spec.run_as or 'poppy'}", "NoNewPrivileges=yes"]
    lines += ["", "[Install]", f"WantedBy={_target(spec)}", ""]
    return "\n".join(lines)


def units(spec: ServiceSpec) -> dict[str, str]:
    """Unit name -> its text, for what ``spec`` asks."""
    out = {UNIT: serve_unit(spec)}
    if spec.jupyter:
        out[JUPYTER_UNIT] = jupyter_unit(spec)
    return out


def _target(spec: ServiceSpec) -> str:
    return "default.target" if spec.user else "multi-user.target"
