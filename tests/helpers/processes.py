"""Child processes of the tests: start one with piped text streams, read a pty until a text
shows, and leave nothing running."""

from __future__ import annotations

import os
import pty
import select
import subprocess
import time
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from tests.helpers.waiting import REPLY_FLOOR_ENV, reply_floor_env, scaled


def read_until(
    fd: int,
    text: str | None,
    timeout_s: float = 60,
    proc: subprocess.Popen[Any] | None = None,
) -> str:
    """What ``fd`` gives until ``text`` shows (None: until it ends), ``proc`` ends, or timeout."""
    seen = b""
    deadline = time.monotonic() + scaled(timeout_s)
    while (text is None or text.encode() not in seen) and time.monotonic() < deadline:
        ready, _, _ = select.select([fd], [], [], 0.2)
        if ready:
            try:
                chunk = os.read(fd, 4096)
            except OSError:
                break
            if not chunk:
                break
            seen += chunk
        elif proc is not None and proc.poll() is not None:
            break
    return seen.decode(errors="replace")


def reap(proc: subprocess.Popen[Any]) -> None:
    """Kill ``proc`` if it still runs, wait for it, and close its pipes."""
    if proc.poll() is None:
        proc.kill()
    proc.wait()
    for stream in (proc.stdin, proc.stdout, proc.stderr):
        if stream is not None:
            stream.close()


def with_reply_floor(env: Mapping[str, str] | None) -> dict[str, str]:
    """``env`` (None: this process's) with the first-reply floor of a `poppy` child whose
    motors are an emulator (``POPPY_REPLY_FLOOR_S``): the one measured now, or the one ``env``
    gives when higher (``tests.helpers.cli.ENV`` carries the floor of the load at its import,
    which a load come since makes short)."""
    full = dict(os.environ if env is None else env)
    measured = reply_floor_env()[REPLY_FLOOR_ENV]
    try:
        given = float(full.get(REPLY_FLOOR_ENV, ""))
    except ValueError:
        given = 0.0
    if given < float(measured):
        full[REPLY_FLOOR_ENV] = measured
    return full


def start(
    argv: Sequence[str], env: Mapping[str, str] | None = None, *, stdin: int | None = None
) -> subprocess.Popen[str]:
    """``argv`` started with its stdout and stderr piped as text (``env``: its environment,
    None for this process's; either way with the load's reply floor, ``with_reply_floor``;
    ``stdin``: e.g. ``subprocess.DEVNULL``)."""
    return subprocess.Popen(
        list(argv),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        stdin=stdin,
        text=True,
        env=with_reply_floor(env),
    )


def start_on_pty(
    argv: Sequence[str], env: Mapping[str, str] | None = None
) -> tuple[subprocess.Popen[bytes], int, int]:
    """``argv`` started on a new pseudo-terminal (its stdin, stdout and stderr), with the
    load's reply floor in ``env`` (``with_reply_floor``).

    Returns:
        The process, the pty's master side (read what it prints, write what it types) and its
        slave side, which the caller closes (at once, or after looking at the terminal's modes).
    """
    master, slave = pty.openpty()
    proc = subprocess.Popen(
        list(argv),
        stdin=slave,
        stdout=slave,
        stderr=slave,
        env=with_reply_floor(env),
        close_fds=True,
    )
    return proc, master, slave


def served_urls(lines: Iterable[str]) -> list[str]:
    """The ``http://`` URLs ``poppy serve`` prints, read up to its ``docs:`` line."""
    urls: list[str] = []
    for line in lines:
        if line.startswith("docs: "):
            break
        if line.startswith("http://"):
            urls.append(line.strip())
    return urls
