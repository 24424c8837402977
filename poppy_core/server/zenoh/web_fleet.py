"""``GET /api/v1/web/fleet``: the robots the served robot's Zenoh session sees, for its page."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from fastapi import APIRouter, Request  # noqa: TID253 (the server room is FastAPI's)

from poppy_core import checks, zenoh_wire

if TYPE_CHECKING:
    from fastapi import FastAPI

    from poppy_core.server.zenoh.robot_node import ZenohRobotServer

ASK_TIMEOUT_S = 0.5
router = APIRouter(prefix="/web", tags=["web page"])


def fleet_of(node: ZenohRobotServer) -> list[dict[str, Any]]:
    """Every robot alive on the network (this one too): name, creature, health, page."""
    alive = set(node.seen())
    found = zenoh_wire.descriptions(node.session, ASK_TIMEOUT_S)
    robots = []
    for name in sorted(alive | set(found)):
        described = found.get(name, {})
        health = described.get("health", {})
        robots.append(
            {
                "name": name,
                "self": name == node.name,
                "creature": str(described.get("creature", "")),
                "ok": bool(health.get("ok", False)),
                "page": checks.peer_page(described.get("page"), announced_hosts(name, described)),
            }
        )
    return robots


def announced_hosts(name: str, described: dict[str, Any]) -> list[str]:
    """Where a robot says it is: ``NAME.local``, its host name, its Zenoh endpoints' hosts
    (``tcp/192.168.1.7:7447``, ``tcp/[fe80::1]:7447#iface=wlan0``)."""
    host = str(described.get("host", ""))
    hosts = [f"{name}.local", host, f"{host}.local"] if host else [f"{name}.local"]
    for endpoint in described.get("endpoints", []):
        address = str(endpoint).split("#", 1)[0].split("/", 1)[-1]
        hosts.append(address.rsplit(":", 1)[0].strip("[]"))
    return hosts


@router.get("/fleet", summary="The robots on this robot's Zenoh network and their pages")
def fleet(request: Request) -> list[dict[str, Any]]:
    """Empty when the robot is not served on Zenoh."""
    node = getattr(request.app.state, "zenoh", None)
    return fleet_of(node) if node is not None else []


def add_fleet_route(app: FastAPI, node: ZenohRobotServer) -> None:
    """Answer ``/api/v1/web/fleet`` from ``node``'s session."""
    app.state.zenoh = node
    app.include_router(router, prefix="/api/v1")
