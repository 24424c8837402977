"""A long-lived child process that answers questions, one JSON line each way (stdlib only).

A Python start in LeRobot's venv costs seconds of CPU (torch's imports): a test module asks
one child all its questions instead of starting one per question. The child script calls
``serve(commands)`` (``load_serve`` in it loads this file by its path: LeRobot's venv has a
``tests`` package of its own); the test talks to it through ``JsonChild``.
"""

from __future__ import annotations

import json
import os
import queue
import subprocess
import sys
import tempfile
import threading
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any

READY = {"ready": True}


def serve(commands: dict[str, Callable[..., Any]], warm: Callable[[], None] | None = None) -> None:
    """The child's loop: each stdin line ``{"args": [COMMAND, ARG...], "env": {...}}`` runs
    ``commands[COMMAND](*ARGS)`` with ``env`` added to the environment meanwhile; its result,
    or ``{"error": TRACEBACK}``, is one line on the original stdout. Whatever the commands
    print goes to stderr, so that it never breaks an answer. ``warm``: imports done before
    the first question (while the test prepares it)."""
    answers = os.fdopen(os.dup(1), "w", encoding="utf-8")
    os.dup2(2, 1)
    sys.stdout = sys.stderr
    if warm is not None:
        warm()
    answers.write(json.dumps(READY) + "\n")
    answers.flush()
    for line in sys.stdin:
        question = json.loads(line)
        added: dict[str, str] = question.get("env") or {}
        before = {key: os.environ.get(key) for key in added}
        os.environ.update(added)
        try:
            name, *args = question["args"]
            answer = commands[name](*args)
        except BaseException:  # the test shows it; the child answers the next question
            answer = {"error": traceback.format_exc()}
        finally:
            for key, value in before.items():
                if value is None:
                    os.environ.pop(key, None)
                else:
                    os.environ[key] = value
        answers.write(json.dumps(answer) + "\n")
        answers.flush()


class JsonChild:
    """``python SCRIPT serve`` started now (its imports run while the test prepares its first
    question): ``ask(...)`` sends a question, returns its JSON answer."""

    def __init__(self, python: Path, script: Path, env: dict[str, str]) -> None:
        # here, not at the top: the serving side loads this file by path, without `tests`
        from tests.helpers.no_real_time import without_real_time

        self._stderr = tempfile.TemporaryFile()  # noqa: SIM115 (closed by close())
        self.process = subprocess.Popen(
            [str(python), str(script), "serve"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self._stderr,
            text=True,
            env=env,
            preexec_fn=without_real_time,  # a peer's AV1 encoder must not go SCHED_FIFO
        )
        self._lines: queue.Queue[str] = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()
        self._ready = False

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            self._lines.put(line)
        self._lines.put("")  # the child ended

    def _next(self, timeout: float) -> dict[str, Any]:
        try:
            line = self._lines.get(timeout=timeout)
        except queue.Empty:
            self.close()
            raise AssertionError(f"no answer in {timeout:.0f} s:\n{self.stderr_tail()}") from None
        assert line, f"the child ended:\n{self.stderr_tail()}"
        answer: dict[str, Any] = json.loads(line)
        return answer

    def ask(
        self, *args: str, env: dict[str, str] | None = None, timeout: float = 600
    ) -> dict[str, Any]:
        """The answer to ``COMMAND ARG...`` (``env``: variables set while it runs); a command
        that raised fails the test with its traceback."""
        if not self._ready:
            assert self._next(timeout) == READY
            self._ready = True
        assert self.process.stdin is not None
        self.process.stdin.write(json.dumps({"args": list(args), "env": env or {}}) + "\n")
        self.process.stdin.flush()
        answer = self._next(timeout)
        assert "error" not in answer, answer["error"] + self.stderr_tail()
        return answer

    def stderr_tail(self, chars: int = 3000) -> str:
        self._stderr.seek(0)
        return self._stderr.read().decode(errors="replace")[-chars:]

    def close(self) -> None:
        """Ends the child (its stdin closed: it returns; killed if it lingers)."""
        if self.process.stdin is not None and not self.process.stdin.closed:
            self.process.stdin.close()
        try:
            self.process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        self._stderr.close()
