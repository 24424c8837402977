"""The robot's settings as the page shows and changes them: name, Wi-Fi, services, token, version.

``RobotSettings`` decides who may change what and logs every change; the OS is reached through
``settings_os.SystemTools`` only. A change needs the server to have been started with
``--token`` (the token middleware then refuses every request without it) and a machine with
NetworkManager and systemd; elsewhere the settings are shown read-only with the reason.
"""

from __future__ import annotations

import dataclasses
import logging
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path
from typing import TYPE_CHECKING, Any

from poppy_core import checks
from poppy_core.checks import robot_name, robot_name_of_host
from poppy_core.errors import ArgumentError, ConfigError, FileError
from poppy_core.server import serve_options
from poppy_core.server.errors import ApiError
from poppy_core.server.origins import OriginPolicy
from poppy_core.server.settings_os import SystemToolError, SystemTools

if TYPE_CHECKING:
    from poppy_core.server.announce import Announcer

logger = logging.getLogger(__name__)

SERVICE_UNITS = {"jupyter": "poppy-jupyter.service"}
"""Service -> its systemd unit (``poppy service install --jupyter`` writes it)."""
SERVED_OPTIONS = {"snap": "--snap", "zmq": "--zmq"}
"""Services served by ``poppy.service`` itself: changed in its settings file (``poppy serve
--settings``), then the service restarts."""
ZMQ_WITH_TOKEN = (
    "ZMQ is not turned on from the page of a robot that requires a token: pypot's ZMQ API has "
    "no token, anyone on the network could move the robot"
)
"""Why the page's ZMQ switch only turns ZMQ off (every change from the page needs a token)."""
SERVICE_UNIT = "poppy.service"
"""The installed service (``poppy service install``), restarted after a change of its files."""


def poppy_version() -> str:
    """The installed poppy's version (``unknown`` in a source tree never installed)."""
    try:
        return metadata.version("poppy")
    except metadata.PackageNotFoundError:
        return "unknown"


@dataclass
class ServedRobot:
    """What the composition root tells the settings about the robot it serves."""

    name: str | None = None
    protocols: tuple[str, ...] = ()
    token_required: bool = False
    policies: list[OriginPolicy] = field(default_factory=list)
    """The Host and Origin rules of every server of the robot (REST and WebSocket, Snap!)."""
    announcer: Announcer | None = None
    version: str = field(default_factory=poppy_version)
    settings_file: Path | None = None
    """The serve options file (``poppy serve --settings``): Snap! and ZMQ are switched there."""
    token_file: Path | None = None
    """The token file (``poppy serve --token-file``): the token is changed there."""
    on_rename: list[Callable[[str], None]] = field(default_factory=list)
    """Called with the new name when the page renames the robot (the Zenoh node serves under
    it from then on)."""

    def named(self, name: str) -> None:
        """The robot is now ``name`` (an mDNS name won, a new name set): the Host check
        accepts it from now on."""
        self.name = name
        for policy in self.policies:
            policy.with_names([name])


class RobotSettings:
    """The settings of one served robot.

    Args:
        system: the OS adapter (by default the machine's own tools).
    """

    def __init__(self, system: SystemTools | None = None) -> None:
        self.system = system or SystemTools()
        self.served = ServedRobot()
        self._files = threading.Lock()
        """One change of the service's files at a time (two pages: neither undoes the other)."""

    # -- reading -------------------------------------------------------------------------------

    def overview(self) -> dict[str, Any]:
        """Everything the settings panel shows, and whether (and why not) it can change it
        (a service the page may not turn on has a ``reason``)."""
        missing = self.system.unavailable()
        reason = self._without_token() or missing
        how = "settings" if self.served.settings_file is not None else None
        services: dict[str, Any] = {
            name: {"on": name in self.served.protocols, "unit": None, "how": how or f"serve {flag}"}
            for name, flag in SERVED_OPTIONS.items()
        }
        if self.served.token_required:
            services["zmq"]["reason"] = ZMQ_WITH_TOKEN
        for name, unit in SERVICE_UNITS.items():
            active = self.system.service_active(unit) if missing is None else None
            services[name] = {"on": active, "unit": unit, "how": "systemctl"}
        return {
            "editable": reason is None,
            "reason": reason,
            "name": self.served.name,
            "hostname": self.system.hostname(),
            "announced": self.served.announcer is not None,
            "services": services,
            "token_required": self.served.token_required,
            "token_changeable": self.served.token_required and self.served.token_file is not None,
            "restarts": self.system.own_unit == SERVICE_UNIT,
            "version": self.served.version,
        }

    def _without_token(self) -> str | None:
        if self.served.token_required:
            return None
        return (
            "this server was started without --token: settings are changed only on a "
            "robot whose server asks for a token (poppy service install --require-token)"
        )

    def wifi(self) -> dict[str, Any]:
        """Networks in range and saved ones (a read: it needs NetworkManager, not a token)."""
        self._check_system()
        return {
            "networks": [vars(n) for n in self.system.networks()],
            "saved": [vars(s) for s in self.system.saved()],
        }

    # -- changing ------------------------------------------------------------------------------

    def check_change(self) -> None:
        """Refuse a change (403 without a token, 409 without the OS's tools)."""
        self._check_token()
        self._check_system()

    def _check_token(self) -> None:
        if not self.served.token_required:
            raise ApiError(
                "forbidden",
                "settings are changed only on a server started with --token",
                tip="restart the server with --token (poppy service install --require-token)",
            )

    def _check_system(self) -> None:
        reason = self.system.unavailable()
        if reason is not None:
            raise ApiError("conflict", reason, tip="the settings are read-only here")

    def set_name(self, text: str, who: str) -> str:
        """Rename the machine and the robot's mDNS name at once; returns the name announced."""
        try:
            name = robot_name(text)
        except ValueError as exc:
            raise ApiError("invalid", str(exc)) from None
        self.check_change()
        self.system.set_hostname(name)
        announcer = self.served.announcer
        won = announcer.rename(name) if announcer is not None else name
        self.served.named(won)
        for rename in self.served.on_rename:
            rename(name)
        logger.warning("settings: %s renamed the robot %s (announced as %s.local)", who, name, won)
        return won

    def join(self, ssid: str, password: str | None, who: str) -> None:
        """Join a Wi-Fi network (and remember it); no password (or "") for an open one."""
        ssid = _checked(checks.wifi_ssid, ssid, "ssid")
        if password:
            password = _checked(checks.wifi_password, password, "password")
        self.check_change()
        self.system.join(ssid, password or None)
        logger.warning("settings: %s joined the Wi-Fi network %r", who, ssid)

    def forget(self, name: str, who: str) -> None:
        """Forget a saved Wi-Fi network (only one: never the Ethernet or another connection)."""
        name = _checked(checks.one_line, name, "name")
        self.check_change()
        saved = [s.name for s in self.system.saved()]
        if name not in saved:
            raise ApiError(
                "invalid",
                f"{name!r} is not a saved Wi-Fi network (saved: {', '.join(saved) or 'none'})",
            )
        self.system.forget(name)
        logger.warning("settings: %s forgot the Wi-Fi network %r", who, name)

    def hotspot(self, on: bool, password: str | None, who: str) -> str | None:
        """Set up (or remove) the access point named after the robot; returns its name."""
        if on:
            password = _checked(checks.wifi_password, password, "the access point's password")
        self.check_change()
        if not on:
            self.system.remove_hotspot()
            logger.warning("settings: %s removed the fallback access point", who)
            return None
        assert password is not None
        ssid = self.served.name or robot_name_of_host(self.system.hostname())
        self.system.set_hotspot(ssid, password)
        logger.warning("settings: %s set up the fallback access point %r", who, ssid)
        return ssid

    def set_service(self, service: str, on: bool, who: str) -> bool:
        """Start a service's unit, or stop it (until the next boot); Snap! and ZMQ are
        switched in the settings file and ``poppy.service`` restarts. Returns True when the
        server restarts now."""
        unit = SERVICE_UNITS.get(service)
        if unit is None:
            if service in SERVED_OPTIONS:
                return self._set_option(service, on, who)
            known = ", ".join([*SERVICE_UNITS, *SERVED_OPTIONS])
            raise ApiError("not_found", f"no service {service!r} (services: {known})")
        self.check_change()
        self.system.set_service(unit, on)
        logger.warning("settings: %s turned %s %s", who, service, "on" if on else "off")
        return False

    def _set_option(self, service: str, on: bool, who: str) -> bool:
        path = self.served.settings_file
        if path is None:
            raise ApiError(
                "conflict",
                f"{service} is an option of this server's command line ({SERVED_OPTIONS[service]}):"
                " it was started without --settings",
                tip="install the service (poppy service install) to switch it from the page",
            )
        self._check_token()
        if service == "zmq" and on and self.served.token_required:
            raise ApiError(
                "conflict", ZMQ_WITH_TOKEN, tip="use the REST API or Zenoh, which ask for the token"
            )
        try:
            with self._files:
                options = serve_options.read_options(path)
                changed = dataclasses.replace(options, **{service: on})
                serve_options.write_options(path, changed)
        except (ConfigError, FileError) as exc:
            raise ApiError(
                "conflict", str(exc), tip="the settings file could not be changed"
            ) from None
        logger.warning("settings: %s turned %s %s (%s)", who, service, "on" if on else "off", path)
        return self._restart(path)

    def set_token(self, token: str, who: str) -> bool:
        """Write a new token in the token file; the server restarts with it (True), or takes
        it at its next start (False)."""
        try:
            serve_options.check_token(token)
        except ValueError as exc:
            raise ApiError("invalid", str(exc)) from None
        self._check_token()
        path = self.served.token_file
        if path is None:
            raise ApiError(
                "conflict",
                "this server's token was given on its command line (--token), not in a file",
                tip="install the service (poppy service install --require-token) to change it here",
            )
        try:
            serve_options.write_token(path, token)
        except FileError as exc:
            raise ApiError(
                "conflict", str(exc), tip="the token file could not be changed"
            ) from None
        logger.warning("settings: %s changed the token (%s)", who, path)
        return self._restart(path)

    def _restart(self, path: Path) -> bool:
        """Restart ``poppy.service`` when this server is it; False when it is not."""
        if self.system.own_unit != SERVICE_UNIT:
            logger.warning("settings: %s changed; it applies when this server starts again", path)
            return False
        try:
            self.system.restart_later(SERVICE_UNIT)
        except SystemToolError as exc:
            raise ApiError(
                "conflict",
                f"saved in {path}, but {exc}",
                tip="it applies at the next start (`poppy service restart` restarts it now)",
            ) from None
        logger.warning("settings: %s restarts to apply it", SERVICE_UNIT)
        return True


def _checked(rule: Callable[[Any, str], str], value: object, field: str) -> str:
    """``rule(value, field)``, its ArgumentError a 422 with its one line."""
    try:
        return rule(value, field)
    except ArgumentError as exc:
        raise ApiError("invalid", str(exc)) from None
