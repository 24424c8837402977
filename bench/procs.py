"""Child processes of the benchmarks: a free TCP port, a process stopped as Ctrl-C would, and
a child run from the repository for the length of a ``with`` block."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from bench.registry import POPPY_PYTHON, REPO_ROOT, BenchContext

SERVE_ERGO_JR = ("-m", "poppy_cli", "serve", "--sim", "--profile", "ergo-jr")
"""poppy's arguments serving a virtual Ergo Jr (after its interpreter)."""


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on now."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def served_ergo(
    kind: str, ctx: BenchContext, pypot_program: str, port: int, *flags: str
) -> list[str]:
    """The command line of a virtual Ergo Jr served on ``port``: ``poppy serve --sim --profile
    ergo-jr FLAGS`` (``kind`` "poppy"), else ``pypot_program`` (Python source taking the port)
    run by the peers' interpreter."""
    if kind == "poppy":
        return [str(POPPY_PYTHON), *SERVE_ERGO_JR, *flags]
    return [str(ctx.peers_python), "-c", pypot_program, str(port)]


def interrupt(proc: subprocess.Popen[Any], timeout_s: float = 10.0) -> None:
    """SIGINT (as Ctrl-C), wait up to ``timeout_s``, then kill; the process is reaped."""
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
    try:
        proc.wait(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


@contextmanager
def child(
    args: list[str],
    *,
    stdout: int = subprocess.DEVNULL,
    env: Mapping[str, str] | None = None,
    stop_timeout_s: float = 10.0,
    cwd: Path | None = None,
) -> Iterator[subprocess.Popen[str]]:
    """``args`` run from the repository, or ``cwd`` (text, stderr piped, ``env`` added to this
    process's); when the block ends: stopped by ``interrupt`` and its pipes closed."""
    proc = subprocess.Popen(
        args,
        cwd=cwd or REPO_ROOT,
        stdout=stdout,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, **env} if env is not None else None,
    )
    try:
        yield proc
    finally:
        interrupt(proc, stop_timeout_s)
        for stream in (proc.stdout, proc.stderr):
            if stream is not None:
                stream.close()
