"""`poppy fleet router`: a Zenoh router on this computer, for the robots and `poppy fleet`."""

from __future__ import annotations

import signal
import threading

import typer

from poppy_cli.output import EXIT_USAGE, error_line


def router(
    listen: list[str] | None = typer.Option(
        None,
        "--listen",
        help="Where to listen (repeat it); default tcp/0.0.0.0:7447, Zenoh's port on every "
        "IPv4 interface. Robots: poppy serve --zenoh --zenoh-connect tcp/THIS-HOST:7447.",
    ),
) -> None:
    """Run a Zenoh router (what zenohd does) until Ctrl-C: the robots and the fleet commands
    connect to it, and it relays between them."""
    from poppy_core.errors import ConfigError, MissingExtraError
    from poppy_core.zenoh_router import DEFAULT_LISTEN, open_router

    endpoints = tuple(listen or DEFAULT_LISTEN)
    stop = threading.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.set())
    try:
        session = open_router(endpoints)
    except (ConfigError, MissingExtraError) as exc:
        error_line(str(exc))
        raise typer.Exit(EXIT_USAGE) from None
    try:
        print(f"zenoh router {session.zid()} listening on {', '.join(endpoints)}", flush=True)
        while not stop.wait(0.5):
            pass
    finally:
        session.close()  # type: ignore[no-untyped-call]
