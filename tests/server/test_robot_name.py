"""A named robot (``poppy serve --name NAME``): the Host check answers ``NAME`` and
``NAME.local``, the pages the robot serves under its name on any port are its own, and a page
of another site is still refused; unnamed, ``poppy.local`` stays refused on a loopback server."""

from __future__ import annotations

import pytest

from poppy_core.checks import robot_name
from poppy_core.server import OriginPolicy
from poppy_core.server.origins import Verdict

HOST = b"poppy.local:8080"


def _policy(name: str | None = "poppy") -> OriginPolicy:
    return OriginPolicy.for_server("127.0.0.1", name=name).with_ports([8080, 9009])


@pytest.mark.parametrize("host", [b"poppy.local:8080", b"poppy.local", b"POPPY.local.", b"poppy"])
def test_a_named_robot_answers_its_name(host: bytes) -> None:
    assert _policy().host_allowed(host)


def test_an_unnamed_loopback_server_refuses_poppy_local() -> None:
    assert not OriginPolicy.for_server("127.0.0.1").host_allowed(HOST)
    assert not _policy().host_allowed(b"evil.example:8080")


@pytest.mark.parametrize("origin", [b"http://poppy.local:8080", b"http://poppy.local:9009"])
def test_pages_of_the_robot_on_its_servers_ports_are_its_own(origin: bytes) -> None:
    assert _policy().verdict(origin, HOST, 8080) is Verdict.OWN


@pytest.mark.parametrize(
    "origin", [b"http://poppy.local:2280", b"https://poppy.local", b"http://poppy:2280"]
)
def test_pages_of_the_robots_name_on_other_ports_are_its_own_with_cors(origin: bytes) -> None:
    assert _policy().verdict(origin, HOST, 8080) is Verdict.SIBLING


@pytest.mark.parametrize(
    "origin",
    [
        b"http://evil.example:2280",
        b"http://poppy.local.evil.example:2280",
        b"http://other.local:2280",
        b"http://127.0.0.1:2280",  # another program of this machine is not the robot's page
        b"ftp://poppy.local:2280",
    ],
)
def test_pages_of_other_sites_stay_refused(origin: bytes) -> None:
    assert _policy().verdict(origin, HOST, 8080) is Verdict.FOREIGN


def test_an_unnamed_robot_does_not_trust_poppy_local_pages() -> None:
    policy = OriginPolicy.for_server("0.0.0.0", allow_hosts=["poppy.local"]).with_ports([8080])
    assert policy.verdict(b"http://poppy.local:2280", HOST, 8080) is Verdict.FOREIGN


def test_the_name_won_after_a_conflict_is_accepted_too() -> None:
    policy = _policy()
    assert not policy.host_allowed(b"poppy-2.local:8080")
    policy.with_names(["poppy-2"])
    assert policy.host_allowed(b"poppy-2.local:8080")
    sibling = policy.verdict(b"http://poppy-2.local:2280", b"poppy-2.local:8080", 8080)
    assert sibling is Verdict.SIBLING


@pytest.mark.parametrize("text", ["", "-poppy", "poppy-", "po ppy", "poppy.example", "*", "a" * 64])
def test_a_name_that_is_not_one_dns_label_is_refused(text: str) -> None:
    with pytest.raises(ValueError, match="is not a robot name"):
        robot_name(text)


def test_names_are_kept_lower_case_without_local() -> None:
    assert robot_name("Ergo-2.local.") == "ergo-2"
