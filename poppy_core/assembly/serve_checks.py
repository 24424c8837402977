"""The rules a ``ServeSpec`` checks itself with when it is made: ports that clash, origins and
Host names that are not ones, and the warnings of a robot exposed to the network or to every
web page. ``poppy serve`` only maps its flags to a spec, so the CLI and Python callers of
``serve()`` and ``PoppyErgoJr(use_http=True)`` get the same lines (an ``ArgumentError``, a
``ValueError``, in Python; exit 2 in the CLI, the flag named before the line)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from poppy_core.errors import ArgumentError

if TYPE_CHECKING:
    from poppy_core.assembly.serve_spec import Listen, ServeSpec

KINDS = {"http": "HTTP", "ws": "WebSocket", "zmq": "ZMQ", "snap": "Snap!", "foxglove": "Foxglove"}
"""What each listening server is called in the lines below."""
LOOPBACK_HOSTS = frozenset({"127.0.0.1", "localhost", "::1"})
ANY_INTERFACE = frozenset({"", "0.0.0.0", "::"})
ANY_ORIGIN = "*"

PROTOCOLS = ("http", "ws", "zmq", "snap", "zenoh", "ros2", "foxglove")
"""pypot's attribute names of the servers (``robot.http``...), ``zenoh``, ``ros2`` and
``foxglove``, in the order they start."""


def check_ports(spec: ServeSpec) -> None:
    """Refuse a port given twice: an HTTP port among its aliases, or two servers on one port
    of one address (0, a free port each, may repeat).

    Raises:
        ArgumentError: ``field`` names the server whose port clashes (``http``, ``ws``...).
    """
    http = spec.http
    if http is not None:
        given = [p for p in (http.port, *spec.http_alias_ports) if p != 0]
        twice = sorted({p for p in given if given.count(p) > 1})
        if twice:
            raise ArgumentError(
                f"the HTTP port {twice[0]} is given twice: give each port once",
                field="http",
                value=twice[0],
            )
    seen: list[tuple[str, str, int]] = []
    for kind, where in spec.listens().items():
        for port in _ports(spec, kind, where):
            for other, host, taken in seen:
                if port == taken and _same_address(where.host, host):
                    raise ArgumentError(_clash(kind, other, port), field=kind, value=port)
        seen += [(kind, where.host, p) for p in _ports(spec, kind, where)]


def _ports(spec: ServeSpec, kind: str, where: Listen) -> list[int]:
    ports = [where.port, *(spec.http_alias_ports if kind == "http" else ())]
    return [p for p in ports if p != 0]


def _same_address(a: str, b: str) -> bool:
    return a == b or a in ANY_INTERFACE or b in ANY_INTERFACE


def _clash(kind: str, other: str, port: int) -> str:
    why = (
        " (the HTTP server streams the same state at /api/v1/ws)"
        if {kind, other} == {"ws", "http"}
        else ""
    )
    return (
        f"the {KINDS[kind]} port {port} is also the {KINDS[other]} port: choose another port{why}"
    )


def check_foxglove(spec: ServeSpec) -> None:
    """Refuse a Foxglove server off loopback while a token is required: foxglove-sdk's
    WebSocket server has no authentication, so it would let others past the token.

    Raises:
        ArgumentError: ``field`` is ``host``.
    """
    where = spec.foxglove
    if where is None or not spec.token or where.host.strip("[]") in LOOPBACK_HOSTS:
        return
    raise ArgumentError(
        "the Foxglove server cannot require the token (foxglove-sdk's WebSocket server has no "
        f"authentication): it serves on loopback only, not on {where.host}; reach it through an "
        "SSH tunnel (ssh -L 8765:127.0.0.1:8765 ...) or serve without a token",
        field="host",
        value=where.host,
    )


def check_origins(spec: ServeSpec) -> None:
    """Refuse an origin in ``cors`` or a name in ``allow_hosts`` that is not one.

    Raises:
        ArgumentError: ``field`` is ``cors`` or ``allow_hosts``.
    """
    if not spec.cors and not spec.allow_hosts:
        return  # nothing to check: the server library is not loaded for nothing
    from poppy_core.server.host_names import normalize_host, normalize_origin

    for origin in spec.cors:
        try:
            normalize_origin(origin)
        except ValueError as exc:
            raise ArgumentError(
                _with_hint(exc, origin, "an origin such as https://snap.berkeley.edu, or '*'"),
                field="cors",
                value=origin,
            ) from None
    for host in spec.allow_hosts:
        try:
            normalize_host(host)
        except ValueError as exc:
            raise ArgumentError(
                _with_hint(exc, host, "a host name such as poppy.local, or '*'"),
                field="allow_hosts",
                value=host,
            ) from None


def _with_hint(exc: ValueError, given: str, hint: str) -> str:
    text = str(exc)
    return text if "give" in text else f"{given!r}: {text}: give {hint}"


def exposure(spec: ServeSpec) -> list[str]:
    """What a server reachable from the network, or open to every page, lets others do: one
    line each (none for a robot served on loopback to its own pages)."""
    lines = []
    zmq = spec.zmq
    if zmq is not None and zmq.host not in LOOPBACK_HOSTS:
        lines.append(
            f"serving the ZMQ API on {zmq.host}: it has no token, anyone who can reach this "
            "machine can move the robot; keep it on 127.0.0.1 unless the network is yours"
        )
    foxglove = spec.foxglove
    if foxglove is not None and foxglove.host not in LOOPBACK_HOSTS:
        lines.append(
            f"serving Foxglove on {foxglove.host}: it has no authentication, anyone who can "
            "reach this machine sees the robot and its camera (it takes no command)"
        )
    elif foxglove is not None and spec.token:
        lines.append(
            "the Foxglove server cannot ask for the token: on loopback, every program and web "
            "page of this machine sees the robot and its camera (it takes no command)"
        )
    moving = {k: w for k, w in spec.listens().items() if k != "foxglove"}
    public = sorted({w.host for w in moving.values() if w.host not in LOOPBACK_HOSTS})
    if public and not spec.token:
        lines.append(
            f"serving on {', '.join(public)} without a token: anyone who can reach this machine "
            "can move the robot (and write its EEPROM); give a token or keep 127.0.0.1"
        )
    if any(origin.strip() == ANY_ORIGIN for origin in spec.cors):
        lines.append(
            "cors '*': every web page you open can move the robot; allow the origins you use "
            "instead (e.g. https://snap.berkeley.edu)"
        )
    return lines


def require_extras(spec: ServeSpec) -> None:
    """Import the libraries of every server ``spec`` asks for (each serving extra brings the
    ``server`` one), so that a missing extra is one line before a robot is built, not after its
    start-up.

    Raises:
        MissingExtraError: the extra's one line (``poppy_core.extras.require``).
    """
    from poppy_core.extras import require

    if not any(getattr(spec, name) is not None for name in PROTOCOLS):
        return
    require("fastapi", "uvicorn", extra="server", feature="the web servers")
    if spec.zmq is not None:
        require("zmq", extra="zmq", feature="pypot's ZMQ server")
    if spec.zenoh is not None or spec.ros2 is not None:
        require("zenoh", extra="fleet")
    if spec.ros2 is not None:
        require("rosbags", extra="ros2")
    if spec.foxglove is not None:
        require("foxglove", extra="foxglove")
    if spec.announce:
        require("zeroconf", extra="appliance")
