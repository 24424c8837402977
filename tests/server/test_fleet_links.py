"""A peer robot's ``page`` on the robot's page (issue 35.4): a peer's description is anyone's
text on the network, so its page is a link only when http(s) to the peer's own announced
address; ``javascript:`` or another site (a page phishing the token) is dropped."""

from __future__ import annotations

from typing import Any

import pytest

from poppy_core import checks, zenoh_wire
from poppy_core.server.zenoh.web_fleet import announced_hosts, fleet_of

HOSTS = ["jr-b.local", "jr-b", "192.168.1.7", "fe80::1"]


@pytest.mark.parametrize(
    ("page", "shown"),
    [
        ("http://192.168.1.7:8080", True),
        ("https://jr-b.local/", True),
        ("http://JR-B.local:80/#motors", True),
        ("http://[fe80::1]:8080", True),
        ("javascript:alert(document.cookie)", False),
        ("JavaScript://192.168.1.7/%0aalert(1)", False),
        ("http://evil.example/login", False),  # another site: it could ask for the token
        ("http://192.168.1.7.evil.example/", False),
        ("http://192.168.1.7@evil.example/", False),
        ("http://user:pw@192.168.1.7/", False),
        ("http://0.0.0.0:8080", False),  # in a browser, the viewer's own machine
        ("http://192.168.1.7:99999", False),
        ("http://192.168.1.7/\nx", False),
        ("data:text/html,<script>", False),
        ("//192.168.1.7/", False),
        (None, False),
        (42, False),
    ],
)
def test_a_peer_page_is_a_link_only_to_the_peer_s_own_address(page: object, shown: bool) -> None:
    assert checks.peer_page(page, HOSTS) == (page if shown else None)


def test_the_announced_hosts_are_the_name_the_host_and_the_endpoints() -> None:
    described = {
        "host": "ergo-b",
        "endpoints": ["tcp/192.168.1.7:7447", "tcp/[fe80::1]:7447#iface=wlan0", "udp/10.0.0.2:1"],
    }
    assert announced_hosts("jr-b", described) == [
        "jr-b.local",
        "ergo-b",
        "ergo-b.local",
        "192.168.1.7",
        "fe80::1",
        "10.0.0.2",
    ]


class _Node:
    name = "jr-a"
    session = None

    def seen(self) -> list[str]:
        return ["jr-a", "jr-b", "jr-c", "jr-d"]


def test_the_fleet_route_drops_the_pages_no_peer_may_link(monkeypatch: pytest.MonkeyPatch) -> None:
    descriptions: dict[str, dict[str, Any]] = {
        "jr-a": {"page": "http://127.0.0.1:8080", "endpoints": ["tcp/127.0.0.1:7447"]},
        "jr-b": {"page": "http://192.168.1.7:80", "endpoints": ["tcp/192.168.1.7:7447"]},
        "jr-c": {"page": "javascript:alert(1)", "endpoints": ["tcp/192.168.1.8:7447"]},
        "jr-d": {"page": "http://evil.example/", "endpoints": ["tcp/192.168.1.9:7447"]},
    }
    monkeypatch.setattr(zenoh_wire, "descriptions", lambda session, timeout: descriptions)
    pages = {r["name"]: r["page"] for r in fleet_of(_Node())}  # type: ignore[arg-type]
    assert pages == {
        "jr-a": "http://127.0.0.1:8080",
        "jr-b": "http://192.168.1.7:80",
        "jr-c": None,
        "jr-d": None,
    }


def test_only_a_wildcard_listener_is_replaced_by_the_machine_s_addresses() -> None:
    from poppy_core.server.reachable import reachable_endpoints, reachable_url

    mine = ["192.0.2.7", "fe80::2"]
    assert reachable_endpoints(["tcp/127.0.0.1:7447", "tcp/192.168.1.7:1"], mine) == [
        "tcp/127.0.0.1:7447",
        "tcp/192.168.1.7:1",
    ]
    assert reachable_endpoints(["tcp/[::]:7447"], mine) == [
        "tcp/192.0.2.7:7447",
        "tcp/[fe80::2]:7447",
    ]
    assert reachable_endpoints(["tcp/0.0.0.0:7447"], []) == ["tcp/0.0.0.0:7447"]  # no address
    assert reachable_url("http://0.0.0.0:8080/x", mine) == "http://192.0.2.7:8080/x"
    assert reachable_url("http://[::]", ["fe80::2"]) == "http://[fe80::2]"
    assert reachable_url("http://127.0.0.1:8080", mine) == "http://127.0.0.1:8080"
    assert reachable_url(None, mine) is None
