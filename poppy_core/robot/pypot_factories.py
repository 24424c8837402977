"""pypot's robot factories by their names: ``from_json(path)`` and ``from_remote(host, port)``.

``from_config`` itself takes pypot's config dicts and files already (``poppy_core.robot``).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

from poppy_core.errors import ArgumentError
from poppy_core.robot.factory import from_config

if TYPE_CHECKING:
    from poppy_core.remote import RemoteRobot
    from poppy_core.robot.robot import Robot


def from_json(
    json_file: str | os.PathLike[str],
    sync: bool = True,
    strict: bool = True,
    use_dummy_io: bool = False,
    **options: Any,
) -> Robot:
    """Build a robot from a pypot JSON config file, as ``pypot.robot.from_json`` does.

    Args:
        json_file: the config file (pypot JSON; poppy's YAML works too).
        sync: start the sync loops.
        strict: missing or mismatched motors raise ``SetupError``.
        use_dummy_io: serve the motors from virtual servos instead of hardware.
        **options: passed to ``poppy_core.robot.from_config``.

    Returns:
        The running robot (a plain robot: the creature classes add their behaviours).
    """
    if not isinstance(json_file, str | os.PathLike):
        raise ArgumentError(
            f"from_json takes a file path, not {type(json_file).__name__}: use from_config for "
            "a dict",
            field="json_file", value=json_file,
        )  # fmt: skip
    return from_config(
        os.fspath(json_file), sim=bool(use_dummy_io), strict=strict, start_sync=sync, **options
    )


def from_remote(host: str, port: int = 8080, *, token: str | None = None) -> RemoteRobot:
    """The robot served by ``poppy serve --http`` on ``host:port`` (pypot's ``from_remote``).

    Returns:
        A ``poppy_core.remote.RemoteRobot`` (motors and groups as attributes, over HTTP).

    Raises:
        CommunicationError: nothing answers there, or it is not a poppy server.
    """
    from poppy_core.remote import RemoteRobot

    url = host if "://" in host else f"http://{_bracketed(host)}:{int(port)}"
    return RemoteRobot(url, token=token)


def _bracketed(host: str) -> str:
    return f"[{host}]" if ":" in host and not host.startswith("[") else host
