"""`poppy serve --ros2`: the options of the ROS 2 node (domain, namespace) and its line."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from poppy_core.assembly import ServerSet
    from poppy_core.ros2_wire import Ros2Settings


def ros2_settings(
    ros2: bool,
    domain: int | None,
    namespace: str | None,
    listen: list[str] | None,
    connect: list[str] | None,
    config: Path | None,
    scout: bool,
) -> Ros2Settings | None:
    """The node's settings (None without --ros2). Without any --zenoh-* option the session
    connects to the router on this machine, as rmw_zenoh's nodes do.

    Raises:
        ConfigError: a bad domain, namespace or endpoint (the caller makes it a usage error).
        ValueError: --ros-domain or --ros-namespace without --ros2.
    """
    from poppy_core.ros2_wire import ROUTER, Ros2Settings
    from poppy_core.zenoh_wire import ZenohSettings

    if not ros2:
        if domain is not None or namespace is not None:
            raise ValueError("--ros-domain and --ros-namespace need --ros2")
        return None
    if listen or connect or config or scout:
        zenoh = ZenohSettings(tuple(listen or ()), tuple(connect or ()), config, scout)
    else:
        zenoh = ZenohSettings(connect=(ROUTER,))
    return Ros2Settings(domain=domain or 0, namespace=namespace or "/", zenoh=zenoh)


def announce_ros2(servers: ServerSet) -> None:
    """The node's line: its name, domain and where its session listens or connects."""
    node = servers.ros2
    if node is None:
        return
    zenoh = node.settings.zenoh
    where = ", ".join(
        [*(f"listening on {e}" for e in zenoh.listen)]
        + [f"connecting to {e}" for e in zenoh.connect]
    )
    name = node.name_of("~")
    print(f"ros2: node {name} on domain {node.domain} ({where or 'Zenoh config'})", flush=True)
