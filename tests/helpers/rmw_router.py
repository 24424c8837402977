"""rmw_zenoh's router for the tests: `python -m tests.helpers.rmw_router ENDPOINT` runs Zenoh's
router with the settings of rmw_zenoh's ``DEFAULT_RMW_ZENOH_ROUTER_CONFIG.json5`` (ros2/rmw_zenoh,
rmw_zenoh_cpp/config; what `ros2 run rmw_zenoh_cpp rmw_zenohd` loads), listening on ENDPOINT
(loopback) instead of its ``tcp/[::]:7447``. The settings below are that file's facts, not the
file: the keys it sets away from Zenoh's defaults that bear on who sees whom. Its
``routing/peer/mode: "peer_to_peer"`` is left out: eclipse-zenoh 1.10 has no such key (peer to
peer is its only peer routing), and its gossip ``autoconnect`` takes lists (``["router", "peer"]``)
where the file of the 2024 Jazzy release wrote ``"router|peer"``."""

from __future__ import annotations

import json
import signal
import sys
import threading

RMW_ZENOH_ROUTER = {
    "mode": "router",
    "connect/endpoints": [],
    "scouting/multicast/enabled": False,
    "scouting/gossip/enabled": True,
    "scouting/gossip/multihop": False,
    "scouting/gossip/autoconnect": {"router": [], "peer": ["router", "peer"]},
    "timestamping/enabled": {"router": True, "peer": True, "client": False},
    "timestamping/drop_future_timestamp": False,
    "queries_default_timeout": 10000,
    "routing/router/peers_failover_brokering": True,
    "transport/unicast/max_links": 1,
    "transport/unicast/qos/enabled": True,
    "transport/link/tx/lease": 10000,
    "transport/link/tx/keep_alive": 4,
}


def main(endpoint: str) -> None:
    import zenoh

    config = zenoh.Config()
    for key, value in {**RMW_ZENOH_ROUTER, "listen/endpoints": [endpoint]}.items():
        config.insert_json5(key, json.dumps(value))
    stop = threading.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.set())
    session = zenoh.open(config)
    print(f"rmw_zenoh router listening on {endpoint}", flush=True)
    while not stop.wait(0.5):
        pass
    session.close()  # type: ignore[no-untyped-call]


if __name__ == "__main__":
    main(sys.argv[1])
