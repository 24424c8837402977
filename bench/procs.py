"""Child processes of the benchmarks: a free TCP port, and a process stopped as Ctrl-C would."""

from __future__ import annotations

import signal
import socket
import subprocess
from typing import Any


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on now."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def interrupt(proc: subprocess.Popen[Any], timeout_s: float = 10.0) -> None:
    """SIGINT (as Ctrl-C), wait up to ``timeout_s``, then kill; the process is reaped."""
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
    try:
        proc.wait(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
