"""Run ``poppy emulate`` in its own process: read its pty path, measure its CPU, stop it."""

from __future__ import annotations

import os
import select
import subprocess
from pathlib import Path

from bench.procs import interrupt
from bench.registry import POPPY_CLI

START_TIMEOUT_S = 30.0
STOP_TIMEOUT_S = 10.0


class EmulatorError(RuntimeError):
    """The emulator process could not start."""


class EmulatorProcess:
    """``poppy emulate --motors SPEC --wire-timing --latency-ms N`` as a child process.

    Use it as a context manager: entering starts the process and reads the pty path from its
    first stdout line; leaving sends SIGINT (as Ctrl-C would) and waits for it to exit.

    Attributes:
        motors: the ``--motors`` spec.
        port: the pty path, once started.
    """

    stdin: int = subprocess.DEVNULL
    """What the process reads: a subclass sending it commands sets ``subprocess.PIPE``."""

    def __init__(self, motors: str, *, latency_ms: float = 1.0, wire_timing: bool = True) -> None:
        """Prepare (not start) an emulator serving ``motors``."""
        self.motors = motors
        self.port = ""
        self._args = [
            str(POPPY_CLI),
            "emulate",
            "--motors",
            motors,
            "--latency-ms",
            str(latency_ms),
        ]
        if wire_timing:
            self._args.append("--wire-timing")
        self._proc: subprocess.Popen[str] | None = None

    @property
    def command(self) -> str:
        """The command line, for the report."""
        return " ".join(["poppy", *self._args[1:]])

    def start(self) -> str:
        """Start the process and return the pty path it prints first.

        Raises:
            EmulatorError: it exited or printed nothing within ``START_TIMEOUT_S``.
        """
        self._proc = subprocess.Popen(
            self._args,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            stdin=self.stdin,
            text=True,
        )
        assert self._proc.stdout is not None
        ready, _, _ = select.select([self._proc.stdout], [], [], START_TIMEOUT_S)
        line = self._proc.stdout.readline().strip() if ready else ""
        if not line:
            self.stop()
            raise EmulatorError(f"`{self.command}` printed no port")
        self.port = line
        return line

    def cpu_s(self) -> float:
        """CPU time (user + system) the emulator has used so far (0 when unknown)."""
        if self._proc is None:
            return 0.0
        try:
            fields = Path(f"/proc/{self._proc.pid}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            return 0.0
        # proc(5): after the command name, utime and stime are fields 12 and 13 (0-based 11, 12).
        ticks = int(fields[11]) + int(fields[12])
        return ticks / os.sysconf("SC_CLK_TCK")

    def stop(self) -> None:
        """Send SIGINT and wait; kill the process if it does not exit in time."""
        proc, self._proc = self._proc, None
        if proc is None or proc.poll() is not None:
            return
        interrupt(proc, STOP_TIMEOUT_S)
        proc.communicate()

    def __enter__(self) -> EmulatorProcess:
        """Start the emulator."""
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        """Stop the emulator."""
        self.stop()
