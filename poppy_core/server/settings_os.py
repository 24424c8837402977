"""``SystemTools``: the one adapter through which the page's settings reach the OS.

Every call runs one of the OS's own tools, ``hostnamectl`` (the machine's name), ``nmcli``
(NetworkManager: Wi-Fi networks, the robot's fallback access point) and ``systemctl`` (the
services), found on ``PATH``, with a timeout, and fails with one line (``SystemToolError``)
quoting the tool's own. Nothing here decides who may change what (``settings.RobotSettings`` does).
Tests put a recording fake of each tool first on ``PATH`` and check the exact commands.
"""

from __future__ import annotations

import logging
import os
import shutil
import socket
import subprocess
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from poppy_core.errors import PoppyError

logger = logging.getLogger(__name__)

TOOLS = ("hostnamectl", "nmcli", "systemctl")
TIMEOUT_S = 60.0
"""Joining a Wi-Fi network waits for DHCP: nmcli's own wait is 90 s, most take a few."""
HOTSPOT = "poppy-hotspot"
"""The NetworkManager connection of the robot's own access point."""
HOTSPOT_PRIORITY = "-100"
"""Lower than any network joined (0): NetworkManager starts the access point only when no
known network answers."""
WIFI_TYPE = "802-11-wireless"
PSK_SETTING = "802-11-wireless-security.psk"
"""A WPA key's line in an ``nmcli ... passwd-file`` is ``802-11-wireless-security.psk:KEY``."""
SECRET_AFTER = ("password", "wifi-sec.psk")
"""Arguments whose next argument is a secret, never logged."""


class SystemToolError(PoppyError):
    """An OS tool is missing, refused, failed or took too long."""


@dataclass(frozen=True)
class Network:
    """A Wi-Fi network in range."""

    ssid: str
    signal: int
    security: str
    in_use: bool


@dataclass(frozen=True)
class SavedNetwork:
    """A Wi-Fi connection NetworkManager knows (joins by itself when in range)."""

    name: str
    priority: int


def split_terse(line: str) -> list[str]:
    """One line of ``nmcli -t`` output: fields split on ``:``, ``\\:`` and ``\\\\`` unescaped."""
    fields, current, escaped = [], [], False
    for char in line:
        if escaped:
            current.append(char)
            escaped = False
        elif char == "\\":
            escaped = True
        elif char == ":":
            fields.append("".join(current))
            current = []
        else:
            current.append(char)
    fields.append("".join(current))
    return fields


def user_manager(cgroup: str) -> bool:
    """True when ``/proc/self/cgroup``'s text says a user's systemd runs this process
    (``poppy service install --user``): its units are then reached with ``systemctl --user``."""
    return "/user@" in cgroup


def unit_of(cgroup: str) -> str | None:
    """The systemd service running this process, from ``/proc/self/cgroup``'s text (None
    outside one: a terminal's session or scope)."""
    for line in cgroup.splitlines():
        last = line.rsplit("/", 1)[-1].strip()
        if last.endswith(".service") and not last.startswith("user@"):
            return last
    return None


def _own_cgroup() -> str:
    try:
        return Path("/proc/self/cgroup").read_text(encoding="utf-8", errors="replace")
    except OSError:
        return ""


def printable_command(argv: Sequence[str]) -> str:
    """``argv`` as logged: the argument after ``password`` or ``wifi-sec.psk`` hidden."""
    shown = list(argv)
    for i, arg in enumerate(shown[:-1]):
        if arg in SECRET_AFTER:
            shown[i + 1] = "***"
    return " ".join(shown)


class SystemTools:
    """The OS's tools, run one command at a time.

    Args:
        user_units: reach the services with ``systemctl --user``; by default when this process
            runs under a user's systemd.
        timeout_s: the longest a command may take.
        cgroup: ``/proc/self/cgroup``'s text (read when None): which systemd service, of the
            system or of a user, runs this process.
    """

    def __init__(
        self,
        user_units: bool | None = None,
        timeout_s: float = TIMEOUT_S,
        cgroup: str | None = None,
    ) -> None:
        cgroup = _own_cgroup() if cgroup is None else cgroup
        self.user_units = user_manager(cgroup) if user_units is None else user_units
        self.own_unit = unit_of(cgroup)
        """The service running this server (``poppy.service`` under the installed service)."""
        self.timeout_s = timeout_s

    # -- running -------------------------------------------------------------------------------

    def run(self, *argv: str, stdin: str | None = None) -> str:
        """Run ``argv`` and return its standard output; ``stdin``: text given on its standard
        input (a secret, never on the command line).

        Raises:
            SystemToolError: the tool is missing, exits non-zero or outlasts the timeout.
        """
        tool = shutil.which(argv[0])
        shown = printable_command(argv)
        if tool is None:
            raise SystemToolError(f"{argv[0]} is not installed here: {shown} cannot run")
        logger.info("running %s", shown)
        try:
            done = subprocess.run(
                [tool, *argv[1:]],
                input=stdin,
                capture_output=True,
                text=True,
                errors="replace",
                timeout=self.timeout_s,
                check=False,
                env={**os.environ, "LC_ALL": "C"},
            )
        except subprocess.TimeoutExpired:
            raise SystemToolError(f"{shown} took longer than {self.timeout_s:g} s") from None
        except OSError as exc:
            raise SystemToolError(f"{shown} could not run: {exc.strerror or exc}") from None
        if done.returncode != 0:
            said = (done.stderr or done.stdout).strip().splitlines()
            reason = said[-1] if said else f"exit status {done.returncode}"
            raise SystemToolError(f"{shown} failed: {reason}")
        return done.stdout

    def unavailable(self) -> str | None:
        """Why settings cannot be changed on this machine, or None when they can."""
        missing = [t for t in TOOLS if shutil.which(t) is None]
        if missing:
            return (
                f"{' and '.join(missing)} not found: the settings are changed from the page on "
                "a machine with NetworkManager and systemd (a Raspberry Pi OS robot)"
            )
        try:
            running = self.run("nmcli", "-t", "-f", "RUNNING", "general").strip()
        except SystemToolError as exc:
            return str(exc)
        if running != "running":
            return "NetworkManager is not running here: start it to set the Wi-Fi from the page"
        return None

    # -- the name ------------------------------------------------------------------------------

    def hostname(self) -> str:
        """This machine's name."""
        return socket.gethostname()

    def set_hostname(self, name: str) -> None:
        """Rename the machine now (no reboot): ``hostnamectl set-hostname NAME``."""
        self.run("hostnamectl", "set-hostname", name)

    # -- Wi-Fi ---------------------------------------------------------------------------------

    def networks(self) -> list[Network]:
        """The Wi-Fi networks in range, strongest first (one entry per name)."""
        out = self.run("nmcli", "-t", "-f", "IN-USE,SSID,SIGNAL,SECURITY", "device", "wifi", "list")
        seen: dict[str, Network] = {}
        for line in out.splitlines():
            fields = split_terse(line)
            if len(fields) != 4 or not fields[1]:
                continue
            in_use, ssid, signal, security = fields
            network = Network(
                ssid, int(signal) if signal.isdigit() else 0, security or "open", in_use == "*"
            )
            old = seen.get(ssid)
            if old is None or network.signal > old.signal or network.in_use:
                seen[ssid] = network
        return sorted(seen.values(), key=lambda n: (-n.signal, n.ssid))

    def saved(self) -> list[SavedNetwork]:
        """The Wi-Fi connections NetworkManager knows (the access point included)."""
        out = self.run("nmcli", "-t", "-f", "NAME,TYPE,AUTOCONNECT-PRIORITY", "connection", "show")
        found = []
        for line in out.splitlines():
            fields = split_terse(line)
            if len(fields) == 3 and fields[1] == WIFI_TYPE:
                priority = fields[2].lstrip("-")
                found.append(SavedNetwork(fields[0], int(fields[2]) if priority.isdigit() else 0))
        return found

    def join(self, ssid: str, password: str | None) -> None:
        """Join ``ssid`` now and remember it.

        An open network: ``nmcli device wifi connect SSID``. A WPA one: a connection named
        ``SSID`` is made without its key (``nmcli connection add``), then started with the key
        in a ``passwd-file`` that only this user can read (``nmcli connection up ... passwd-file
        FILE``, nmcli's documented way to give secrets at activation; NetworkManager keeps a key
        given so for the next joins). The key is never on a command line, where any user of the
        machine sees it in the process list. A refused key leaves no connection behind.
        """
        if not password:
            self.run("nmcli", "device", "wifi", "connect", ssid)
            return
        if any(s.name == ssid for s in self.saved()):
            self.forget(ssid)  # its old key would be tried first
        self.run(
            "nmcli",
            "connection",
            "add",
            "type",
            "wifi",
            "ifname",
            self.wifi_device(),
            "con-name",
            ssid,
            "ssid",
            ssid,
            "wifi-sec.key-mgmt",
            "wpa-psk",
        )
        with tempfile.TemporaryDirectory(prefix="poppy-wifi-") as folder:  # mode 0700
            secrets = Path(folder) / "secrets"
            fd = os.open(secrets, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
            with os.fdopen(fd, "w", encoding="utf-8") as out:
                out.write(f"{PSK_SETTING}:{password}\n")
            try:
                self.run("nmcli", "connection", "up", "id", ssid, "passwd-file", str(secrets))
            except SystemToolError:
                try:
                    self.forget(ssid)
                except SystemToolError as exc:
                    logger.warning("the refused connection %r stays: %s", ssid, exc)
                raise

    def forget(self, name: str) -> None:
        """Forget a saved network: ``nmcli connection delete id NAME``."""
        self.run("nmcli", "connection", "delete", "id", name)

    def wifi_device(self) -> str:
        """The first Wi-Fi interface (``wlan0`` on a Raspberry Pi)."""
        for line in self.run("nmcli", "-t", "-f", "DEVICE,TYPE", "device").splitlines():
            fields = split_terse(line)
            if len(fields) == 2 and fields[1] == "wifi":
                return fields[0]
        raise SystemToolError("no Wi-Fi interface here (nmcli -t -f DEVICE,TYPE device)")

    def set_hotspot(self, ssid: str, password: str) -> None:
        """Make (or remake) the fallback access point ``ssid``: NetworkManager starts it only
        when no network it knows answers (lowest autoconnect priority).

        The connection is made without its key (``nmcli connection add``), then the key is
        set through nmcli's connection editor reading its commands on standard input
        (``nmcli connection edit id poppy-hotspot``: ``set 802-11-wireless-security.psk KEY``,
        ``save persistent``, ``quit``; the way Ansible's nmcli module keeps secrets off the
        command line). Starting it now with a ``passwd-file``, as ``join`` does, would take the
        robot off the network it is on. A key that cannot be set leaves no access point behind.
        """
        if any(s.name == HOTSPOT for s in self.saved()):
            self.forget(HOTSPOT)
        self.run(
            "nmcli",
            "connection",
            "add",
            "type",
            "wifi",
            "ifname",
            self.wifi_device(),
            "con-name",
            HOTSPOT,
            "autoconnect",
            "yes",
            "ssid",
            ssid,
            "connection.autoconnect-priority",
            HOTSPOT_PRIORITY,
            "802-11-wireless.mode",
            "ap",
            "ipv4.method",
            "shared",
            "wifi-sec.key-mgmt",
            "wpa-psk",
        )
        commands = f"set {PSK_SETTING} {password}\nsave persistent\nquit\n"
        try:
            self.run("nmcli", "connection", "edit", "id", HOTSPOT, stdin=commands)
        except SystemToolError:
            try:
                self.forget(HOTSPOT)
            except SystemToolError as exc:
                logger.warning("the access point without its key stays: %s", exc)
            raise

    def remove_hotspot(self) -> None:
        """Remove the fallback access point (nothing when there is none)."""
        if any(s.name == HOTSPOT for s in self.saved()):
            self.forget(HOTSPOT)

    # -- services ------------------------------------------------------------------------------

    def _systemctl(self, *argv: str) -> list[str]:
        return ["systemctl", *(["--user"] if self.user_units else []), *argv]

    def service_active(self, unit: str) -> bool:
        """True when ``unit`` runs (``systemctl is-active``: inactive and unknown are False)."""
        try:
            return self.run(*self._systemctl("is-active", unit)).strip() == "active"
        except SystemToolError:
            return False

    def set_service(self, unit: str, on: bool) -> None:
        """Start ``unit``, or stop it (``systemctl start|stop``): what the polkit rule of
        ``poppy service install`` grants; whether it starts at boot stays as installed."""
        self.run(*self._systemctl("start" if on else "stop", unit))

    def restart_later(self, unit: str) -> None:
        """Ask systemd to restart ``unit`` and return at once (``systemctl restart --no-block``):
        the unit may be the one running this server, which answers before it is stopped."""
        self.run(*self._systemctl("restart", "--no-block", unit))
