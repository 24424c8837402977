"""A Zenoh router in a poppy process (`poppy fleet router`): the classroom's one meeting point.

The router is Zenoh's own runtime in router mode (what ``zenohd`` runs). Its settings follow the
facts of rmw_zenoh's router default (``rmw_zenoh_cpp/config/DEFAULT_RMW_ZENOH_ROUTER_CONFIG.json5``
in ros2/rmw_zenoh): multicast scouting off, gossip on (rmw_zenoh's peers learn each other's
endpoints through it), ``peers_failover_brokering`` on, samples timestamped. The endpoints are
the caller's; the lease is poppy's (``zenoh_wire.DEFAULT_LEASE_MS``) so that a robot that
vanishes leaves the fleet within it.
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

from poppy_core.errors import ConfigError
from poppy_core.extras import require
from poppy_core.zenoh_wire import DEFAULT_LEASE_MS, ZenohSettings, zenoh_message

if TYPE_CHECKING:
    import zenoh

DEFAULT_LISTEN = ("tcp/0.0.0.0:7447",)
"""Every IPv4 interface, on Zenoh's port: the robots and the teacher's commands connect here."""


def router_config(listen: tuple[str, ...] = DEFAULT_LISTEN) -> zenoh.Config:
    """The configuration of a router listening on ``listen``.

    Raises:
        ConfigError: an endpoint that is not a Zenoh endpoint.
        MissingExtraError: eclipse-zenoh is not installed (the ``fleet`` extra).
    """
    ZenohSettings(listen=listen)  # checks the endpoints
    require("zenoh", extra="fleet")
    import zenoh

    config = zenoh.Config()
    for key, value in (
        ("mode", '"router"'),
        ("listen/endpoints", json.dumps(list(listen))),
        ("connect/endpoints", "[]"),
        ("scouting/multicast/enabled", "false"),
        ("scouting/gossip/enabled", "true"),
        ("routing/router/peers_failover_brokering", "true"),
        ("timestamping/enabled", "true"),
        ("transport/link/tx/lease", str(DEFAULT_LEASE_MS)),
    ):
        config.insert_json5(key, value)
    return config


def open_router(listen: tuple[str, ...] = DEFAULT_LISTEN) -> zenoh.Session:
    """A router listening on ``listen``, routing until it is closed.

    Raises:
        ConfigError: a bad endpoint, or one it cannot listen on (a busy port).
        MissingExtraError: eclipse-zenoh is not installed (the ``fleet`` extra).
    """
    config = router_config(listen)
    import zenoh

    try:
        return zenoh.open(config)
    except zenoh.ZError as exc:
        raise ConfigError(
            f"cannot start the Zenoh router ({zenoh_message(exc)}): check --listen "
            "(is another router on that port?)",
            field="listen",
        ) from None
