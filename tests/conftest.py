"""Suite-wide: the slow marker for ``make test-fast``, and a guard against tests stuck in C.

A test is slow when it starts programs (``poppy`` subprocesses, tmux, a browser), runs a Textual
app, an HTTP server or MuJoCo physics, moves whole simulated creatures, or waits for things on
purpose (bus loss, soak-like runs, fuzzing). Whole folders and modules of that kind are listed
here, so that a test added to them is marked too; a single slow test elsewhere takes
``@pytest.mark.slow``. ``make test`` runs everything.
"""

from __future__ import annotations

import atexit
import faulthandler
import os
import shutil
import signal
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

import _pytest.unraisableexception as _pytest_unraisable
import pytest
from hypothesis import settings

from poppy_core.dataset.realtime import calling_thread_realtime, undo_realtime
from tests.helpers import timing
from tests.helpers.parts import GL_MODULES, UnknownPart, current_part, outside_part
from tests.helpers.tls import share_one_context
from tests.helpers.waiting import load_factor, runnable_now

TESTS = Path(__file__).resolve().parent
share_one_context()  # ~30 ms of CPU per httpx client otherwise (tests/helpers/tls.py)
SLOW_FOLDERS = {"cli", "creatures", "gym", "server", "sim", "teleop", "tui"}
SLOW_MODULES = {
    "emulator/test_emulator_threads.py",
    "kinematics/test_sim_chain.py",
    "robot/test_bus_loss.py",
    "robot/test_config_hypothesis.py",
}
# `make test` runs the suite in parallel worker processes (pytest-xdist, `--dist loadgroup`).
# A module's tests stay in one worker: they share module-scoped servers, robots and MuJoCo
# models, and some of them a fixed loopback port (tests/tui/test_snapshots.py). The modules that
# drive Debian's chromium share one worker, so two browsers never compete for the CPU.
BROWSER_MODULES = {
    "server/test_browser.py",
    "server/test_snap_browser.py",
    "server/test_web_page.py",
    "server/test_mdns_browser.py",
    "server/test_settings_page.py",
    "server/test_web_view.py",
    "server/test_web_page_layout.py",
}
# pytest-timeout (120 s, by signal) stops a test that waits in Python. A thread stuck inside a
# C library (an OpenGL driver, a serial ioctl) never sees the signal; this watchdog then prints
# every thread's stack and exits, so CI reports where it hung instead of running out its budget.
# Both limits say how long is too long on an idle machine: each test gets them times the load
# factor measured when it starts (a busy machine makes a test late, not stuck).
HANG_LIMIT_S = 600
# Property tests run Hypothesis's default number of examples; `HYPOTHESIS_PROFILE=thorough`
# runs ten times as many (before a release, or when a codec or parser changed). Neither has a
# deadline per example. Tests whose
# examples are costly (a whole HTTP API fuzzed) scale from ``settings.default.max_examples``.
# Bytecode caches are written even when PYTHONDONTWRITEBYTECODE is set (containers set it): without
# them each test process compiles and assertion-rewrites all 600 test modules again (~10 s of CPU
# a process at collection, 40% of it) and every `poppy` subprocess compiles poppy's modules
# (subprocesses still read them; git ignores them).
sys.dont_write_bytecode = False
# A run started in the background by a non-interactive shell (`.ci/run &`, nohup) inherits SIGINT
# ignored, and so would every `poppy` the tests start (Python then installs no KeyboardInterrupt):
# the Ctrl-C tests would see a command that cannot be interrupted. A handler here is reset to
# the default in each child at exec, where Python installs its own again.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)
# Each test process (each xdist worker too) has user folders of its own: no test reads or
# writes the user's ~/.config/poppy, and parallel workers never share one.
_USER_DIRS = tempfile.mkdtemp(prefix="poppy-tests-user-")
atexit.register(shutil.rmtree, _USER_DIRS, ignore_errors=True)
for _var in ("XDG_CONFIG_HOME", "XDG_DATA_HOME", "XDG_CACHE_HOME", "XDG_STATE_HOME"):
    os.environ[_var] = os.path.join(_USER_DIRS, _var.lower())
# No deadline per example: on a loaded machine (CI, two busy loops) an example is late, never
# wrong; speed goals are the benchmarks'.
settings.register_profile("default", deadline=None)
settings.register_profile("thorough", max_examples=1000, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))


# `make test` runs `-n auto`: two workers per core, idle or busy (its load, less the commands
# tests/together.sh started beside this run, 1.5 per core or more: CI's neighbours, busy
# loops). Three per core were tried on an idle machine, since the suite mostly waits: the run
# took 16 min 29 s where four workers took 13 min 31 s (load 6-13: the load-scaled waits and
# the children's reply floors grew with it; docs/testing.md). PYTEST_XDIST_AUTO_NUM_WORKERS=N
# overrides it.
IDLE_WORKERS_PER_CORE = 2
BUSY_WORKERS_PER_CORE = 2
BUSY_LOAD_PER_CORE = 1.5


@pytest.hookimpl(optionalhook=True)  # an xdist hook: unknown to a run with -p no:xdist
def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    del config
    override = os.environ.get("PYTEST_XDIST_AUTO_NUM_WORKERS", "").strip()
    if override.isdigit():
        return int(override)
    cores = os.cpu_count() or 1
    beside = int(os.environ.get("TOGETHER_BESIDE", "0") or 0)  # mypy, the OpenGL tests
    load = max(os.getloadavg()[0], float(runnable_now() - beside))
    busy = load / cores >= BUSY_LOAD_PER_CORE
    return (BUSY_WORKERS_PER_CORE if busy else IDLE_WORKERS_PER_CORE) * cores


def pytest_configure(config: pytest.Config) -> None:
    try:
        current_part()
    except UnknownPart as error:
        raise pytest.UsageError(str(error)) from None
    timing.pytest_configure(config)
    if getattr(config.option, "dist", "no") == "loadgroup":
        # The workers' collection order (longest groups first, pytest_collection_modifyitems)
        # is the order groups are handed out in: xdist must not sort them by test count.
        config.option.loadscopereorder = False
    # pytest collects garbage 5 times at the end of each process, to report the unraisable
    # exceptions of objects freed last; with the heap a worker has then, each pass took 0.2-0.5 s
    # of CPU, in every process at once. One pass frees what the tests left; the four others
    # mostly walked the heap again.
    iterations = getattr(_pytest_unraisable, "gc_collect_iterations_key", None)
    if iterations is not None:
        config.stash[iterations] = 1


def _longest_groups_first(items: list[pytest.Item], groups: dict[pytest.Item, str]) -> None:
    """Sorts ``items`` in the order their groups are handed out (``timing.handout_order``:
    xdist hands a worker a whole group, and the long ones must not start last); each group's
    tests keep their order."""
    counts: dict[str, int] = {}
    for item in items:
        counts[groups[item]] = counts.get(groups[item], 0) + 1
    rank = {group: index for index, group in enumerate(timing.handout_order(counts))}
    items.sort(key=lambda item: rank[groups[item]])


def pytest_ignore_collect(collection_path: Path, config: pytest.Config) -> bool | None:
    """Leaves out the test modules of the other part when ``POPPY_TEST_PART`` names one
    (tests/helpers/parts.py: `make test` runs the modules that mostly wait beside the rest)."""
    del config
    part = current_part()
    if (
        part is None
        or collection_path.suffix != ".py"
        or not collection_path.name.startswith("test_")
    ):
        return None
    resolved = collection_path.resolve()
    if not resolved.is_relative_to(TESTS):
        return None
    module = resolved.relative_to(TESTS).as_posix()
    source = lambda: resolved.read_text(encoding="utf-8")  # noqa: E731 (read only if needed)
    return True if outside_part(module, part, source) else None


@pytest.hookimpl(tryfirst=True)  # before xdist reads the groups
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    grouped = config.pluginmanager.hasplugin("xdist")
    groups: dict[pytest.Item, str] = {}
    relatives: dict[str, Path | None] = {}  # a module's tests share its path: resolved once
    for item in items:
        path = str(item.path)
        if path not in relatives:
            resolved = Path(path).resolve()
            inside = resolved.is_relative_to(TESTS)
            relatives[path] = resolved.relative_to(TESTS) if inside else None
        relative = relatives[path]
        if relative is None:
            continue
        if relative.parts[0] in SLOW_FOLDERS or relative.as_posix() in SLOW_MODULES:
            item.add_marker(pytest.mark.slow)
        if relative.as_posix() in GL_MODULES:
            item.add_marker(pytest.mark.gl)
        if grouped:
            module = relative.as_posix()
            group = "browser" if module in BROWSER_MODULES else module
            item.add_marker(pytest.mark.xdist_group(group))
            groups[item] = group
    if grouped and os.environ.get("PYTEST_XDIST_WORKER") and len(groups) == len(items):
        _longest_groups_first(items, groups)


def _timeout_s(item: pytest.Item) -> float:
    """The test's pytest-timeout limit (its marker's, else the option's or the ini's), 0: none."""
    marker = item.get_closest_marker("timeout")
    if marker is not None and (marker.args or "timeout" in marker.kwargs):
        value = marker.args[0] if marker.args else marker.kwargs["timeout"]
    else:
        value = item.config.getoption("timeout", None) or item.config.getini("timeout") or 0
    return float(value)


@pytest.hookimpl(hookwrapper=True, tryfirst=True)  # around pytest-timeout's, which reads the mark
def pytest_runtest_protocol(item: pytest.Item) -> Iterator[None]:
    factor = load_factor()
    timeout_s = _timeout_s(item) * factor
    if timeout_s > 0:
        item.add_marker(pytest.mark.timeout(timeout_s), append=False)  # the closest mark wins
    hang_s = max(HANG_LIMIT_S * factor, timeout_s + 60)
    faulthandler.dump_traceback_later(hang_s, exit=True, file=sys.__stderr__)
    try:
        yield
    finally:
        faulthandler.cancel_dump_traceback_later()
        _not_real_time(item)


def _not_real_time(item: pytest.Item) -> None:
    """A library that made this worker real-time (SVT-AV1 does, as root) is undone at once: every
    thread and process the worker starts later would inherit SCHED_FIFO 99, and a busy one would
    hold a core the worker's own threads then never get (stop 37's CI run hung that way)."""
    if calling_thread_realtime():
        undone = undo_realtime()
        said = f"conftest: {item.nodeid} left {undone} thread(s) real-time: undone"
        print(said, file=sys.__stderr__)
