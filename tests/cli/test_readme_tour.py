"""The README's first tour, every command in order, as a new user runs it (issue 25).

The commands are read from README.md ("A first tour" and the Python block after it), so a
command added there is toured too. Each runs in a process of its own against a `poppy emulate
--profile ergo-jr` the tour starts (its pty stands for the README's ``/dev/pts/3``), with stdout
and stderr piped, stdin not a terminal and COLUMNS unset; then the commands whose behaviour a
terminal changes run again, in order, on a pty of their own against a fresh emulator.

Each command must: exit as documented, ask nothing without a terminal (no ``[Y/n]``), print no
traceback, cut no table cell (``…``) nor wrap a line to the 80 columns of a pipe (its output
has as many lines with COLUMNS=1000), and name in its hints only `poppy` commands and options
that exist. Every problem of the whole tour is collected and reported at the end, one per line.

Ports of real hardware are mapped to emulated adapters (``PORT_MAPPINGS`` says which and why).
"""

from __future__ import annotations

import os
import re
import shlex
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import pytest
import typer

from poppy_cli.main import app
from tests.helpers.cli import POPPY, run_poppy_process
from tests.helpers.terminal import CTRL_C, Terminal
from tests.helpers.waiting import MIN_TIMEOUT_S, eventually, reply_floor_env

pytestmark = [pytest.mark.slow, pytest.mark.timeout(600)]

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
README_PTY = "/dev/pts/3"  # the example pty path the README uses for `poppy emulate`'s
PROMPT = re.compile(r"\[[yY]/[nN]\]|\[y/n\]|\(y/n\)")
TRACEBACK = "Traceback (most recent call last)"
CUT = re.compile(r"\S…\s*([│┃]|$)")  # Rich's cut cell ("posit… │"), not a range ("-150 … 150")
# a command a hint names: `poppy ...` in backticks, or after run/restart/try/use
HINT = re.compile(r"`(poppy\s[^`]+)`|\b(?:run|restart|try|use)\s+(poppy(?:\s+[-\w./=,]+)+)")
FIRST_LINE_S = 60  # a loaded machine starts Python, imports, opens a robot: waits, not bounds
RUN_S = 120  # a command not done after this long hangs
WATCH_S = 8  # how long a live table runs (a few seconds, and its robot up on a loaded machine)


# --- the README's commands ------------------------------------------------------------------


def _fenced(section: str, language: str) -> list[str]:
    """The lines of the first ```language block after the heading ``section``."""
    text = README.read_text(encoding="utf-8")
    start = text.index(section)
    block = re.search(rf"```{language}\n(.*?)```", text[start:], re.S)
    assert block is not None, f"README.md: no ```{language} block after {section!r}"
    return block.group(1).splitlines()


@dataclass
class Step:
    """One README line: ``argv`` after `poppy`, ``background`` when it ends in ``&``."""

    line: str
    argv: list[str]
    background: bool

    @property
    def command(self) -> str:
        return " ".join(w for w in self.argv if not w.startswith("-"))[:40]

    def has(self, *words: str) -> bool:
        return any(w in self.argv for w in words)


def tour_steps() -> list[Step]:
    """The tour's `poppy` commands, in order (the venv's activation is this test's interpreter)."""
    steps = []
    for raw in _fenced("## A first tour", "sh"):
        line = re.sub(r"\s+#.*$", "", raw).strip()
        if not line or line.startswith(". ") or line.startswith("source "):
            continue
        background = line.endswith("&")
        words = shlex.split(line.rstrip("&"))
        assert words[0] == "poppy", f"README tour line is not a poppy command: {raw!r}"
        steps.append(Step(raw.strip(), words[1:], background))
    return steps


def python_block() -> str:
    return "\n".join(_fenced("In Python:", "python"))


def test_the_tour_is_read_from_the_readme() -> None:
    steps = tour_steps()
    assert any(s.argv[0] == "emulate" and s.background for s in steps)
    assert any(s.has("--watch") for s in steps)
    assert "from_profile" in python_block()
    for step in steps:  # every hardware port has an emulated stand-in
        for word in step.argv:
            if word.startswith("/dev/") and word != README_PTY:
                assert _adapter_for(step, word) is not None, step.line


# --- emulated stand-ins for the README's hardware -------------------------------------------

# /dev/ttyUSB0 and /dev/ttyUSB1 are adapters with real motors on them. Each command gets the
# emulated motors it was written for, a `poppy emulate` of its own per adapter:
PORT_MAPPINGS: dict[str, tuple[list[str], str]] = {
    # a new MX-28 as it comes out of the box (ID 1, 57600 bps, protocol 1): what `scan
    # --all-bauds` is for (an unknown rate) and what `set-id 1 11 --baud 57600 --protocol 1`
    # renames; scan then set-id share this adapter, as in the README.
    "new-mx28": (["--motors", "MX-28:1", "--baud", "57600"], "a factory-new MX-28"),
    # `motor reset 1 42 --angle-limits -150,150` (poppy-reset-motor: a new motor, ID 1) on
    # another new MX-28: the one above is ID 11 by then, and an XL-320 reaches 149.7° only.
    "another-new-mx28": (["--motors", "MX-28:1", "--baud", "57600"], "another new MX-28"),
    # `calibrate` and teleop's leader: the Ergo Jr of the tour (`poppy emulate` above);
    # teleop's follower (/dev/ttyUSB1): a second emulated Ergo Jr.
    "follower": (["--profile", "ergo-jr"], "a second Ergo Jr"),
}


def _adapter_for(step: Step, port: str) -> str | None:
    """The stand-in of ``port`` in ``step``: a PORT_MAPPINGS key or "tour" (the tour's Ergo Jr)."""
    if port == "/dev/ttyUSB1":
        return "follower"
    if port != "/dev/ttyUSB0":
        return None
    if step.has("--profile", "--leader", "--config"):
        return "tour"
    if step.argv[:2] == ["motor", "reset"]:
        return "another-new-mx28"
    return "new-mx28"


# --- processes ------------------------------------------------------------------------------


class Running:
    """A command in a process of its own: pipes read as it prints, stdin a pipe or nothing."""

    def __init__(self, argv: list[str], env: dict[str, str], cwd: Path, stdin: bool) -> None:
        self.argv = argv
        self.proc = subprocess.Popen(
            [*POPPY, *argv],
            stdin=subprocess.PIPE if stdin else subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            env=env,
            cwd=cwd,
            start_new_session=True,  # a Ctrl-C of the test run is not theirs
        )
        self.finished = False
        self.code: int | None = None
        self.out: list[bytes] = []
        self.err: list[bytes] = []
        self._readers = [
            self._read(self.proc.stdout, self.out),
            self._read(self.proc.stderr, self.err),
        ]

    @staticmethod
    def _read(stream: IO[bytes] | None, into: list[bytes]) -> threading.Thread:
        def pump() -> None:
            assert stream is not None
            for chunk in iter(lambda: stream.read1(4096), b""):  # type: ignore[attr-defined]
                into.append(chunk)

        thread = threading.Thread(target=pump, daemon=True)
        thread.start()
        return thread

    @property
    def stdout(self) -> str:
        return b"".join(self.out).decode(errors="replace")

    @property
    def stderr(self) -> str:
        return b"".join(self.err).decode(errors="replace")

    def wait_for(self, text: str, timeout_s: float = FIRST_LINE_S) -> bool:
        """Whether ``text`` showed on stdout or stderr before the command ended or time ran out."""
        if timeout_s < MIN_TIMEOUT_S:  # a plain wait: `eventually` waits at least 15 s
            deadline = time.monotonic() + timeout_s
            while time.monotonic() < deadline and text not in self.stdout + self.stderr:
                time.sleep(0.1)
            return text in self.stdout or text in self.stderr
        eventually(
            lambda: text in self.stdout or text in self.stderr or self.proc.poll() is not None,
            timeout_s,
        )
        time.sleep(0.05)
        return text in self.stdout or text in self.stderr

    def type(self, keys: bytes) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.write(keys)
        self.proc.stdin.flush()

    def interrupt(self, signum: int = signal.SIGINT) -> None:
        if self.proc.poll() is None:
            self.proc.send_signal(signum)

    def finish(self, timeout_s: float = RUN_S) -> int | None:
        """The exit code, or None when it hangs (then it is killed)."""
        if self.finished:
            return self.code
        try:
            code: int | None = self.proc.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()
            code = None
        for reader in self._readers:
            reader.join(5)
        if self.proc.stdin is not None:
            self.proc.stdin.close()
        self.finished, self.code = True, code
        return code

    def stop(self) -> None:
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()


@dataclass
class Tour:
    """The user's machine: a fresh home, the emulated robot and adapters, what went wrong."""

    home: Path
    problems: list[str] = field(default_factory=list)
    ports: dict[str, str] = field(default_factory=dict)  # README port or stand-in -> pty
    background: list[tuple[Step, Running]] = field(default_factory=list)
    emulators: list[Running] = field(default_factory=list)

    @property
    def env(self) -> dict[str, str]:
        env = {k: v for k, v in os.environ.items() if k not in ("COLUMNS", "LINES")}
        for var in ("XDG_CONFIG_HOME", "XDG_DATA_HOME", "XDG_CACHE_HOME", "XDG_STATE_HOME"):
            env[var] = str(self.home / var.lower())
        env.pop("POPPY_MOVES_DIR", None)
        env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
        env["NO_COLOR"] = "1"
        env["BROWSER"] = "true"  # `--open` runs `true URL`: no browser on the test machine
        # the motors are `poppy emulate` processes a busy machine runs late: the commands wait
        # for their first replies as long as the load measured now needs (POPPY_REPLY_FLOOR_S)
        env.update(reply_floor_env())
        return env

    def problem(self, step: Step | str, what: str) -> None:
        line = step.line if isinstance(step, Step) else step
        self.problems.append(f"{line}\n      -> {what}")

    def emulate(self, *args: str) -> str:
        """Start `poppy emulate ARGS`; its pty path (its first line)."""
        emulator = Running(["emulate", *args], self.env, self.home, stdin=False)
        self.emulators.append(emulator)
        # its first line on stdout (a warning on stderr may come first on a busy machine)
        eventually(
            lambda: "\n" in emulator.stdout or emulator.proc.poll() is not None, FIRST_LINE_S
        )
        assert "\n" in emulator.stdout, f"poppy emulate {args} printed no path: {emulator.stderr}"
        return emulator.stdout.splitlines()[0].strip()

    def argv(self, step: Step) -> list[str]:
        """The step's words with the README's ports replaced by the emulated ones."""
        words = []
        for word in step.argv:
            if word == README_PTY:
                word = self.ports["tour"]
            elif word.startswith("/dev/tty"):
                adapter = _adapter_for(step, word)
                assert adapter is not None, f"no stand-in for {word} in {step.line}"
                if adapter not in self.ports:
                    args, what = PORT_MAPPINGS[adapter]
                    self.ports[adapter] = self.emulate(*args)
                    print(f"{word} of `{step.command}`: {what}, {self.ports[adapter]}")
                word = self.ports[adapter]
            words.append(word)
        return words

    def close(self) -> None:
        for _, running in self.background:
            running.stop()
        for emulator in self.emulators:
            emulator.interrupt()
            code = emulator.finish(30)
            if code != 0:  # serves until Ctrl-C, then ends normally
                self.problems.append(f"poppy {shlex.join(emulator.argv)}: exit {code} on Ctrl-C")


@pytest.fixture
def tour(tmp_path: Path) -> Iterator[Tour]:
    made = Tour(tmp_path)
    try:
        yield made
    finally:
        made.close()


# --- what every command's output must be ----------------------------------------------------

_commands: dict[str, Any] = {}  # typer's click command of `poppy`


def _cli() -> Any:
    if "" not in _commands:
        _commands[""] = typer.main.get_command(app)
    return _commands[""]


def hint_problem(hint: str) -> str | None:
    """What is wrong with a `poppy ...` command named in a hint (None: it exists, options too)."""
    command = _cli()
    ctx = command.context_class(command, info_name="poppy")
    words = shlex.split(hint)[1:]
    options = {o for p in command.params for o in getattr(p, "opts", [])} | {"--help"}
    for word in words:
        if hasattr(command, "get_command") and not word.startswith("-"):  # a group
            sub = command.get_command(ctx, word)
            if sub is None:
                if word.isidentifier() or re.fullmatch(r"[a-z][a-z-]*", word):
                    return f"`{hint}`: no command {word!r}"
                break
            command = sub
            options = {o for p in command.params for o in getattr(p, "opts", [])} | {"--help"}
            continue
        if word.startswith("-") and not re.fullmatch(r"-\d.*", word):
            name = word.split("=", 1)[0]
            if name not in options and name not in ("--debug", "-v", "-q", "-V"):
                return f"`{hint}`: no option {name} in `{command.name}`"
    return None


def test_hints_are_checked_against_the_cli() -> None:
    assert hint_problem("poppy motor set-return-delay 1-6 0 --port /dev/pts/2") is None
    assert hint_problem("poppy -q robot goto m1=-30 --sim") is None
    assert "no command 'set-delay'" in str(hint_problem("poppy motor set-delay 1-6 0"))
    assert "no option --fix" in str(hint_problem("poppy robot status --fix"))


def check_output(tour: Tour, step: Step, out: str, err: str, *, piped: bool = True) -> None:
    both = out + err
    if TRACEBACK in both:
        tour.problem(step, f"a traceback: {err.strip().splitlines()[-1]!r}")
    # `calibrate` is the one guided procedure: it reads its steps and answers from stdin, a
    # terminal's or a pipe's (how it is scripted; docs/cli.md), so its questions are expected
    if piped and PROMPT.search(both) and step.argv[:1] != ["calibrate"]:
        tour.problem(step, f"asks a question without a terminal: {_line_with(both, PROMPT)!r}")
    if piped:
        for line in both.splitlines():
            if CUT.search(line):
                tour.problem(step, f"a table cell cut: {line.strip()!r}")
                break
        if "\x1b[" in out:
            tour.problem(step, "terminal escape codes written into a pipe")
    for hint in (a or b for a, b in HINT.findall(both)):
        wrong = hint_problem(hint)
        if wrong:
            tour.problem(step, f"a hint names what does not exist: {wrong}")


def _line_with(text: str, pattern: re.Pattern[str]) -> str:
    return next((line for line in text.splitlines() if pattern.search(line)), "").strip()


def check_code(tour: Tour, step: Step, code: int | None, expected: int, err: str) -> None:
    if code is None:
        tour.problem(step, f"hangs (killed after {RUN_S} s); stderr: {err.strip()[-300:]!r}")
    elif code != expected:
        tour.problem(step, f"exit {code}, expected {expected}; stderr: {err.strip()[-300:]!r}")


# --- the tour through pipes -----------------------------------------------------------------

# Commands that change what they act on, or take long: not run a second time at COLUMNS=1000.
QUICK_S = 6.0
NOT_TWICE = {"set-id", "reset", "record", "calibrate", "teleop", "play", "emulate", "serve"}


def run_piped(tour: Tour, step: Step) -> None:
    """Run one README command as a script would, stdout and stderr piped, no terminal."""
    kind = _kind(step)
    if kind == "emulate":
        emulator = Running(step.argv, tour.env, tour.home, stdin=False)
        tour.emulators.append(emulator)
        if not emulator.wait_for("\n"):
            tour.problem(step, f"printed no pty path: {emulator.stderr.strip()!r}")
            pytest.fail("\n".join(tour.problems))
        tour.ports["tour"] = emulator.stdout.splitlines()[0].strip()
        return
    argv = tour.argv(step)
    started = time.monotonic()
    running = Running(argv, tour.env, tour.home, stdin=kind in ("record", "calibrate", "teleop"))
    if step.background:
        tour.background.append((step, running))
        return
    expected = 0
    if kind == "watch":  # a live table until Ctrl-C: 130, as every interrupted command
        running.wait_for("\n", WATCH_S)  # piped, it may print only its last frame, at Ctrl-C
        running.interrupt()
        expected = 130
        if running.finish() == 130 and "m6" not in running.stdout:
            tour.problem(step, f"no table for Ctrl-C: {running.stdout[-300:]!r}")
    elif kind == "serve":  # serves until Ctrl-C: exit 0, `stopped` on stderr (docs/cli.md)
        if not running.wait_for("http://"):
            tour.problem(step, "printed no URL it serves")
        running.interrupt()
        if running.finish() == 0 and "stopped" not in running.stderr:
            tour.problem(step, "did not say `stopped` on Ctrl-C")
    elif kind == "record":  # Enter only stops it on a terminal; Ctrl-C saves and exits 0
        move = Path(tour.env["XDG_DATA_HOME"], "poppy", "moves", f"{step.argv[1]}.move")
        if running.wait_for("recording"):
            time.sleep(1.5)  # a take of a second or so (not an assertion)
        else:
            tour.problem(step, "never said it records")
        running.interrupt()
        if running.finish() == 0 and running.stdout.strip().splitlines()[-1:] != [str(move)]:
            tour.problem(step, f"the last line of stdout is not {move}: {running.stdout!r}")
        frames = re.search(r"recorded (\d+) frames", running.stderr)
        if not frames or int(frames.group(1)) < 2:
            tour.problem(step, f"recorded no take: {running.stderr.strip()[-200:]!r}")
    elif kind == "calibrate":  # answers from stdin: Enter for the posture, then each joint
        running.type(b"\n" * 20)
    elif kind == "teleop":  # Ctrl-C stops it: the follower holds, exit 0
        if not running.wait_for("stops"):
            tour.problem(step, "never said how it stops")
        running.interrupt()
    elif kind == "tui":  # without a terminal: one line saying so, never a screen in a pipe
        expected = 2
        code = running.finish(15)
        check_output(tour, step, running.stdout, running.stderr)
        if code is None:
            tour.problem(step, "hangs drawing its screen into a pipe (killed after 15 s)")
        elif code == 0 or "terminal" not in running.stderr:
            tour.problem(step, f"exit {code} without saying it needs a terminal")
        return
    code = running.finish()
    took = time.monotonic() - started
    print(f"{took:5.1f} s  poppy {shlex.join(argv)}")
    check_code(tour, step, code, expected, running.stderr)
    check_output(tour, step, running.stdout, running.stderr)
    quick = took < QUICK_S  # a long command (a scan at every rate) is not run twice
    if kind == "plain" and code == 0 and quick and not (set(step.argv) & NOT_TWICE):
        _check_width(tour, step, argv, running.stdout)


def _check_width(tour: Tour, step: Step, argv: list[str], narrow: str) -> None:
    """Piped output is whole lines at the data's width: COLUMNS must change no line break."""
    for _ in range(3):
        wide = Running(argv, {**tour.env, "COLUMNS": "1000"}, tour.home, stdin=False)
        wide.finish()
        # a wrap moves line breaks, never words: other words are another answer (a scan on a
        # busy machine that heard a late reply), so the command is asked again
        if wide.stdout.split() == narrow.split():
            break
        narrow_again = Running(argv, tour.env, tour.home, stdin=False)
        narrow_again.finish()
        narrow = narrow_again.stdout
    a, b = narrow.splitlines(), wide.stdout.splitlines()
    if len(a) != len(b):
        longest = max(b, key=len, default="")
        tour.problem(
            step,
            f"piped output wrapped at 80 columns: {len(a)} lines, {len(b)} with COLUMNS=1000 "
            f"(e.g. {longest.strip()[:100]!r})",
        )


def _kind(step: Step) -> str:
    first = step.argv[0]
    if first == "emulate":
        return "emulate"
    if step.has("--watch"):
        return "watch"
    if first in ("serve", "record", "calibrate", "teleop", "tui"):
        return first
    return "plain"


def stop_background(tour: Tour) -> None:
    for step, running in tour.background:
        running.interrupt()
        check_code(tour, step, running.finish(30), 0, running.stderr)
        check_output(tour, step, running.stdout, running.stderr)
    tour.background.clear()


def test_readme_tour_through_pipes(tour: Tour) -> None:
    for step in tour_steps():
        run_piped(tour, step)
    stop_background(tour)
    result = subprocess.run(
        [sys.executable, "-c", python_block()],
        capture_output=True,
        text=True,
        env=tour.env,
        cwd=tour.home,
        timeout=RUN_S,
    )
    python = Step("README's Python block", ["python"], False)
    check_code(tour, python, result.returncode, 0, result.stderr)
    check_output(tour, python, result.stdout, result.stderr)
    if not re.fullmatch(r"-?\d+(\.\d+)?\s*", result.stdout):
        tour.problem(python, f"printed {result.stdout!r}, not m1's position")
    tour.close()
    assert not tour.problems, "the README tour, piped:\n" + "\n".join(tour.problems)


# --- the tour on a terminal -----------------------------------------------------------------


def on_a_terminal(step: Step) -> bool:
    """A command a terminal changes: it may ask (a robot on the emulator's port), it reads keys
    (record, calibrate, teleop, the TUI) or draws live (--watch)."""
    opens_robot = step.has("--profile", "--leader") and any(
        w.startswith("/dev/") for w in step.argv
    )
    return opens_robot or step.has("--watch") or step.argv[0] in ("tui", "record", "teleop")


@dataclass
class Screen:
    """What the pty tour does with a command: ``answers`` to what it asks (each time it shows),
    then ``stop`` (keys typed once its text showed) and the exit code then."""

    answers: list[tuple[str, bytes]]
    stop: tuple[str, bytes] | None
    code: int


def _screen(step: Step) -> Screen:
    kind = _kind(step)
    if kind == "watch":
        return Screen([], ("m6", CTRL_C), 130)
    if kind == "record":
        return Screen([], ("recording", b"\n"), 0)
    if kind == "teleop":
        return Screen([], ("stops", b"\n"), 0)
    if kind == "calibrate":  # the posture, each joint (not moved), then write the profile
        return Screen([("press Enter", b"\n"), ("[y/n]", b"y\n")], None, 0)
    if kind == "tui":
        return Screen([], ("Bus", b"q"), 0)
    return Screen([], None, 0)


RETURN_DELAY = "return delay to 0"


def test_readme_tour_on_a_terminal(tour: Tour) -> None:
    """The tour's commands a terminal changes, in a pty: the README's return-delay question is
    asked once per emulated bus (answered yes, as the README says) and never again; keys stop
    what they say."""
    answered: set[str] = set()  # the ports whose return delay was set
    for step in tour_steps():
        if _kind(step) == "emulate":
            tour.ports["tour"] = tour.emulate(*step.argv[1:])
        elif on_a_terminal(step):
            _on_a_terminal(tour, step, answered)
    tour.close()
    assert not tour.problems, "the README tour, on a terminal:\n" + "\n".join(tour.problems)


def _on_a_terminal(tour: Tour, step: Step, answered: set[str]) -> None:
    """Run ``step`` in a pty, answering and typing what ``_screen`` says."""
    screen = _screen(step)
    stop = screen.stop
    argv = tour.argv(step)
    ports = {w for w in argv if w.startswith("/dev/")}
    may_ask = len(ports - answered)  # once per bus not set yet
    env = {k: v for k, v in tour.env.items() if k not in ("NO_COLOR", "COLUMNS")}
    terminal = Terminal(*argv, env={**env, "LINES": "50"})  # 200 columns
    code: int | None = None
    try:
        seen = 0  # what was shown before this is answered
        deadline = time.monotonic() + RUN_S
        while time.monotonic() < deadline and terminal.proc.poll() is None:
            terminal.read_until("\x00", 0.5)
            new = terminal.text[seen:]
            if RETURN_DELAY in new and PROMPT.search(new):
                if may_ask == 0:
                    tour.problem(step, f"on a terminal: asks again: {_line_with(new, PROMPT)!r}")
                    terminal.type(CTRL_C)
                    break
                may_ask -= 1
                terminal.type(b"y\n")
            elif answer := next((keys for text, keys in screen.answers if text in new), None):
                terminal.type(answer)
            elif stop is not None and stop[0] in new:
                time.sleep(0.5)  # let it record or draw a little first (not an assertion)
                terminal.type(stop[1])
                stop = None
            else:
                continue
            seen = len(terminal.text)
        code = terminal.wait(10)
    except subprocess.TimeoutExpired:
        code = None
    finally:
        terminal.close()
    answered |= ports
    if code is None:
        tour.problem(step, f"on a terminal: still running; it shows {terminal.text[-300:]!r}")
    elif code != screen.code:
        tour.problem(
            step,
            f"on a terminal: exit {code}, expected {screen.code}: {terminal.text.strip()[-300:]!r}",
        )
    if stop is not None:
        tour.problem(step, f"on a terminal: never showed {stop[0]!r}")
    check_output(tour, step, "", terminal.text, piped=False)


def test_tui_without_a_terminal_says_so_at_once() -> None:
    """`poppy tui` piped drew its screen into the pipe and waited there for keys, forever."""
    result = run_poppy_process("tui", "--sim", timeout=60)
    assert result.code == 2
    assert "needs a terminal" in result.stderr and "poppy tui --serve" in result.stderr
    assert result.stdout == ""
