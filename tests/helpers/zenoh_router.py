"""A Zenoh router process on loopback for the tests: `poppy fleet router --listen ENDPOINT`
(Zenoh's router runtime, as zenohd runs it; explicit endpoint, no scouting)."""

from __future__ import annotations

import os
import subprocess
import sys
from typing import Any

from tests.helpers.cli import POPPY, command_env
from tests.helpers.processes import read_until, reap
from tests.helpers.zenoh_served import free_endpoint


class Router:
    """`poppy fleet router` listening on a free loopback endpoint (``rmw``: a router with
    rmw_zenoh's default settings, ``tests.helpers.rmw_router``); ``restart`` keeps it."""

    def __init__(
        self, endpoint: str | None = None, *, rmw: bool = False, start: bool = True
    ) -> None:
        self.endpoint = endpoint or free_endpoint()
        self.rmw = rmw
        self.proc: subprocess.Popen[Any] | None = None
        if start:
            self.start()

    def start(self) -> None:
        argv = (
            [sys.executable, "-m", "tests.helpers.rmw_router", self.endpoint]
            if self.rmw
            else [*POPPY, "fleet", "router", "--listen", self.endpoint]
        )
        self.proc = subprocess.Popen(
            argv,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            env=dict(os.environ, **command_env()),
        )
        assert self.proc.stdout is not None
        seen = read_until(self.proc.stdout.fileno(), "listening on", 60, self.proc)
        assert "listening on" in seen, (seen, self.proc.poll())

    def kill(self) -> None:
        if self.proc is not None:
            reap(self.proc)
            self.proc = None

    def restart(self) -> None:
        self.kill()
        self.start()
