"""The polkit rule that lets a system service's user do what the robot's page asks of the OS."""

from __future__ import annotations

import json
import os
from pathlib import Path

POLKIT_DIR_ENV = "POPPY_POLKIT_DIR"
SYSTEM_POLKIT_DIR = Path("/etc/polkit-1/rules.d")
RULE_FILE = "50-poppy.rules"

# polkit action IDs (systemd's org.freedesktop.systemd1 policy, systemd-hostnamed's
# org.freedesktop.hostname1 and NetworkManager's policy): restart the robot's own units, rename
# the machine, manage Wi-Fi connections and the fallback access point. Nothing else.
UNIT_ACTION = "org.freedesktop.systemd1.manage-units"
UNIT_VERBS = ("start", "stop", "restart")
OS_ACTIONS = (
    "org.freedesktop.hostname1.set-hostname",
    "org.freedesktop.hostname1.set-static-hostname",
    "org.freedesktop.NetworkManager.settings.modify.system",
    "org.freedesktop.NetworkManager.network-control",
    "org.freedesktop.NetworkManager.enable-disable-wifi",
    "org.freedesktop.NetworkManager.wifi.share.open",
    "org.freedesktop.NetworkManager.wifi.share.protected",
)


def polkit_dir() -> Path:
    """Where the rule goes: ``POPPY_POLKIT_DIR``, or /etc/polkit-1/rules.d."""
    given = os.environ.get(POLKIT_DIR_ENV)
    return Path(given) if given else SYSTEM_POLKIT_DIR


def rule_text(user: str, units: tuple[str, ...]) -> str:
    """The rule (polkit's JavaScript) for ``user``: start/stop/restart ``units``, and the
    hostname and NetworkManager actions of the page's settings."""
    return (
        "// Written by `poppy service install`: the robot's page may restart its own services\n"
        "// and change the machine's name and Wi-Fi (docs/appliance.md). Removed by\n"
        "// `poppy service uninstall`.\n"
        "polkit.addRule(function (action, subject) {\n"
        f"  if (subject.user != {json.dumps(user)}) return polkit.Result.NOT_HANDLED;\n"
        f"  if (action.id == {json.dumps(UNIT_ACTION)} &&\n"
        f'      {json.dumps(list(units))}.indexOf(action.lookup("unit")) >= 0 &&\n'
        f'      {json.dumps(list(UNIT_VERBS))}.indexOf(action.lookup("verb")) >= 0) {{\n'
        "    return polkit.Result.YES;\n"
        "  }\n"
        f"  if ({json.dumps(list(OS_ACTIONS))}.indexOf(action.id) >= 0) {{\n"
        "    return polkit.Result.YES;\n"
        "  }\n"
        "  return polkit.Result.NOT_HANDLED;\n"
        "});\n"
    )
