"""The one adapter to systemd: every `systemctl` and `journalctl` call of `poppy service` goes here.

The commands are found on ``PATH`` when called (tests put a recording fake first on ``PATH`` and
check the exact command lines). ``--user`` units go to the user's unit folder and are driven with
``systemctl --user``; system units go to ``/etc/systemd/system``. ``POPPY_UNIT_DIR`` replaces the
folder (an image being built, the tests).
"""

from __future__ import annotations

import os
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

from poppy_core.errors import SetupError

SYSTEM_UNIT_DIR = Path("/etc/systemd/system")
UNIT_DIR_ENV = "POPPY_UNIT_DIR"
TIMEOUT_S = 60.0


class SystemdError(SetupError):
    """systemd is missing, or one of its commands failed (the message says which and why)."""


def unit_dir(user: bool) -> Path:
    """Where the units go: ``POPPY_UNIT_DIR``, the user's unit folder, or /etc/systemd/system."""
    given = os.environ.get(UNIT_DIR_ENV)
    if given:
        return Path(given)
    if not user:
        return SYSTEM_UNIT_DIR
    config = os.environ.get("XDG_CONFIG_HOME") or str(Path.home() / ".config")
    return Path(config) / "systemd" / "user"


@dataclass(frozen=True)
class Systemd:
    """systemd of the system (``user=False``) or of the user's session (``user=True``)."""

    user: bool

    @property
    def scope(self) -> str:
        """``"user"`` or ``"system"``."""
        return "user" if self.user else "system"

    def systemctl(self, *args: str, check: bool = True) -> str:
        """Run ``systemctl [--user] ARGS``; its standard output.

        Raises:
            SystemdError: systemctl is missing, or failed with ``check`` (its message quoted).
        """
        done = self._run("systemctl", self._scoped(args))
        if check and done.returncode != 0:
            said = " ".join((done.stderr or done.stdout).split()) or f"exit {done.returncode}"
            command = " ".join(["systemctl", *self._scoped(args)])
            raise SystemdError(f"`{command}` failed: {said}")
        return done.stdout

    def is_active(self, unit: str) -> bool:
        """True when ``unit`` runs (``systemctl [--user] is-active --quiet UNIT``).

        Raises:
            SystemdError: systemctl is missing.
        """
        return self._run("systemctl", self._scoped(("is-active", "--quiet", unit))).returncode == 0

    def journal(self, unit: str, lines: int, follow: bool) -> int:
        """Show the unit's log (``journalctl``) on this terminal; its exit code.

        Raises:
            SystemdError: journalctl is missing.
        """
        which = ["--user-unit", unit] if self.user else ["--unit", unit]
        args = [*which, "--lines", str(lines), "--no-pager", *(["--follow"] if follow else [])]
        return subprocess.call([_find("journalctl"), *args])

    def _scoped(self, args: tuple[str, ...]) -> list[str]:
        return [*(["--user"] if self.user else []), *args]

    @staticmethod
    def _run(command: str, args: list[str]) -> subprocess.CompletedProcess[str]:
        try:
            return subprocess.run(
                [_find(command), *args],
                capture_output=True,
                text=True,
                timeout=TIMEOUT_S,
                check=False,
            )
        except subprocess.TimeoutExpired:
            raise SystemdError(
                f"`{command} {' '.join(args)}` did not answer in {TIMEOUT_S:g} s"
            ) from None


def _find(command: str) -> str:
    path = shutil.which(command)
    if path is None:
        raise SystemdError(
            f"{command} not found: this machine does not run systemd (poppy service needs it; "
            "start `poppy serve` another way)"
        )
    return path
