"""The schedule leaf: deadlines on a fake clock, rate meter, backoff, the worker's errors."""

from __future__ import annotations

import logging
import threading

import pytest

from poppy_core.errors import ArgumentError
from poppy_core.schedule import (
    Backoff,
    Periodic,
    RateMeter,
    Ticker,
    TickGuard,
    Worker,
    close_all,
)
from tests.helpers.waiting import eventually


def test_periodic_on_a_fake_clock_keeps_the_grid() -> None:
    schedule = Periodic(0.1, 10.0)
    now = 10.0
    runs = []
    while now < 11.0:  # a fake clock stepping 10 ms: runs at each due deadline, none missed
        if schedule.due(now):
            runs.append(round(now, 3))
            schedule.advance(now)
        now = round(now + 0.01, 3)
    assert runs == [round(10.0 + 0.1 * k, 3) for k in range(10)]
    assert schedule.missed == 0
    assert schedule.advance(11.35) == 3  # 11.1, 11.2 and 11.3 came and went
    assert schedule.next_deadline == pytest.approx(11.4)


@pytest.mark.parametrize("period", [0, -1, float("nan"), float("inf"), 1e-6, 1e9])
def test_periodic_refuses_a_period_outside_the_floor(period: float) -> None:
    with pytest.raises(ArgumentError, match="period"):
        Periodic(period, 0.0)


def test_rate_meter_goes_stale() -> None:
    meter = RateMeter(window=5)
    assert meter.rate_at(0.0, 1.0) == 0.0
    for k in range(20):
        meter.tick(k * 0.1)
    assert meter.rate_hz == pytest.approx(10) and meter.count == 20
    assert meter.rate_at(1.95, 0.5) == pytest.approx(10)
    assert meter.rate_at(3.0, 0.5) == 0.0


def test_backoff_doubles_up_to_its_ceiling_and_resets() -> None:
    backoff = Backoff(0.1, 1.0)  # the buses' figures (the fault soak depends on them)
    delays = [backoff.delay_s] + [backoff.failed() for _ in range(6)]
    assert delays == pytest.approx([0.1, 0.2, 0.4, 0.8, 1.0, 1.0, 1.0])
    assert backoff.reset() == 0.1 and backoff.delay_s == 0.1


def test_backoff_refuses_a_ceiling_under_its_first_delay() -> None:
    with pytest.raises(ArgumentError, match="longest delay"):
        Backoff(1.0, 0.5)
    with pytest.raises(ArgumentError, match="first delay"):
        Backoff(0.0, 1.0)


def test_worker_runs_until_stopped() -> None:
    ticks: list[int] = []
    ended = threading.Event()

    def body(stopping: threading.Event) -> None:
        while not stopping.wait(0.005):
            ticks.append(1)

    worker = Worker("test ticker", body, on_exit=ended.set)
    worker.start()
    worker.start()  # no second thread
    assert eventually(lambda: len(ticks) >= 3)
    assert worker.running
    assert worker.stop(timeout_s=5.0) is True
    assert not worker.running and ended.is_set() and worker.error is None


def test_worker_error_is_logged_once_kept_and_raised_to_the_joiner(
    caplog: pytest.LogCaptureFixture,
) -> None:
    def body(stopping: threading.Event) -> None:
        raise RuntimeError("the loop broke")

    worker = Worker("test breaker", body)
    with caplog.at_level(logging.WARNING, logger="poppy_core.schedule"):
        worker.start()
        assert eventually(lambda: not worker.running)
        with pytest.raises(RuntimeError, match="the loop broke"):
            worker.join(timeout_s=5.0)
        with pytest.raises(RuntimeError, match="the loop broke"):
            worker.stop()  # every waiter hears it
    assert isinstance(worker.error, RuntimeError)
    assert worker.close() is True  # an owner's close goes on; the error stays in .error
    warnings = [r for r in caplog.records if "test breaker failed" in r.getMessage()]
    assert len(warnings) == 1 and warnings[0].levelno == logging.WARNING


def test_worker_wait_does_not_raise_and_stop_twice_is_safe() -> None:
    def body(stopping: threading.Event) -> None:
        raise ValueError("bad value")

    worker = Worker("test waiter", body)
    worker.start()
    assert worker.wait(timeout_s=5.0) is True  # the error stays in .error, not raised
    assert isinstance(worker.error, ValueError)
    assert worker.close() is True and worker.close() is True


def test_worker_quiet_errors_are_kept_but_not_logged(caplog: pytest.LogCaptureFixture) -> None:
    def body(stopping: threading.Event) -> None:
        raise ArgumentError("the owner says this one", field="x")

    worker = Worker("test quiet", body, quiet=(ArgumentError,))
    with caplog.at_level(logging.DEBUG, logger="poppy_core.schedule"):
        worker.start()
        with pytest.raises(ArgumentError):
            worker.join(timeout_s=5.0)
    assert not [r for r in caplog.records if "test quiet" in r.getMessage()]


def test_worker_stopped_from_its_own_body_only_asks() -> None:
    answers: list[bool] = []
    holder: list[Worker] = []

    def body(stopping: threading.Event) -> None:
        answers.append(holder[0].stop())  # no "cannot join current thread"
        assert stopping.is_set()

    worker = Worker("test self stop", body)
    holder.append(worker)
    worker.start()
    assert worker.wait(timeout_s=5.0)
    assert answers == [True] and worker.error is None


def test_a_tick_guard_keeps_a_loop_through_failures_logged_once_with_backoff(
    caplog: pytest.LogCaptureFixture,
) -> None:

    guard = TickGuard("loop", first_s=0.001, max_s=0.004)
    stopping = threading.Event()
    calls: list[int] = []

    def failing() -> None:
        calls.append(1)
        raise ValueError("no data")

    caplog.set_level(logging.WARNING, logger="poppy_core.schedule")
    assert [guard.run(failing, stopping) for _ in range(4)] == [False] * 4
    assert guard.backoff.delay_s == 0.004  # doubled up to its longest
    assert guard.health() == {"ok": False, "failures": 4, "last_error": "ValueError: no data"}
    assert guard.run(lambda: None, stopping) is True
    assert guard.health() == {"ok": True, "failures": 4, "last_error": None}
    assert guard.backoff.delay_s == 0.001
    guard.run(failing, stopping)  # a new run of failures is logged again, once
    warned = [r for r in caplog.records if "a tick failed" in r.getMessage()]
    assert len(warned) == 2 and len(calls) == 5


def test_close_all_runs_every_step_and_logs_each_failure_once(
    caplog: pytest.LogCaptureFixture,
) -> None:
    ran: list[str] = []
    log = logging.getLogger("poppy_core.test_close")

    def step(name: str, error: BaseException | None = None) -> tuple[str, object]:
        def run() -> None:
            ran.append(name)
            if error is not None:
                raise error

        return name, run

    steps = [
        step("a", OSError("port gone")),
        step("b", KeyboardInterrupt()),  # Ctrl-C while closing: the rest still closes
        step("c", RuntimeError("")),
        step("d"),
    ]
    with (
        caplog.at_level(logging.WARNING, logger="poppy_core.test_close"),
        pytest.raises(KeyboardInterrupt),
    ):
        close_all(steps, log, "the thing")  # type: ignore[arg-type]
    assert ran == ["a", "b", "c", "d"]
    assert [r.getMessage() for r in caplog.records] == [
        "closing the thing: a failed: port gone",
        "closing the thing: c failed: RuntimeError",
    ]


def test_worker_start_is_atomic(monkeypatch: pytest.MonkeyPatch) -> None:
    """Two threads starting one worker at once start one thread: the second finds it running."""
    from poppy_core.schedule import worker as worker_module

    class SlowThread(threading.Thread):
        def start(self) -> None:  # widens the window between "not running" and "started"
            stopping_wait.wait(0.05)
            super().start()

    stopping_wait = threading.Event()
    runs: list[int] = []
    worker = Worker("once", lambda stopping: (runs.append(1), stopping.wait(5.0)))
    barrier = threading.Barrier(4)

    def start() -> None:
        barrier.wait()
        worker.start()

    starters = [threading.Thread(target=start) for _ in range(4)]  # plain threads
    monkeypatch.setattr(worker_module.threading, "Thread", SlowThread)  # the worker's are slow
    for starter in starters:
        starter.start()
    for starter in starters:
        starter.join(5.0)
    eventually(lambda: len(runs) >= 1)
    threading.Event().wait(0.1)  # a second thread, if any, would have run its body by now
    worker.stop()
    assert runs == [1]


def test_periodic_worker_ticks_until_the_tick_says_done() -> None:
    ticks: list[float] = []

    def tick(now: float) -> bool:
        ticks.append(now)
        return len(ticks) < 5

    worker = Worker.periodic("five", 200.0, tick)
    worker.start()
    assert worker.wait(timeout_s=5.0)
    assert len(ticks) == 5 and ticks == sorted(ticks) and worker.error is None
    assert worker.ticker is not None and worker.ticker.meter.count == 5


def test_periodic_worker_logs_a_failing_tick_once_backs_off_and_resumes(
    caplog: pytest.LogCaptureFixture,
) -> None:
    outcomes = ["fail"] * 4 + ["ok"] * 3
    seen: list[str] = []

    def tick(now: float) -> bool:
        outcome = outcomes[len(seen)]
        seen.append(outcome)
        if outcome == "fail":
            raise OSError("bus away")
        return len(seen) < len(outcomes)

    caplog.set_level(logging.WARNING, logger="poppy_core.schedule")
    worker = Worker.periodic("flaky", 500.0, tick, first_s=0.001, max_s=0.004)
    assert worker.ticker is not None
    worker.start()
    assert worker.wait(timeout_s=5.0)
    assert seen == outcomes and worker.error is None  # the loop lived through the failures
    warned = [r for r in caplog.records if "a tick failed" in r.getMessage()]
    assert len(warned) == 1 and "flaky" in warned[0].getMessage()
    assert worker.ticker.health()["ok"] is True
    assert worker.ticker.health()["failures"] == 4


def test_periodic_worker_shows_a_failing_loop_in_its_health() -> None:
    worker = Worker.periodic("broken", 100.0, lambda now: 1 / 0, first_s=0.001, max_s=0.002)
    assert worker.ticker is not None
    worker.start()
    try:
        eventually(lambda: worker.ticker is not None and worker.ticker.guard.failures >= 3)
        health = worker.ticker.health()
        assert health["ok"] is False and "ZeroDivisionError" in str(health["last_error"])
        assert worker.running  # still retrying
    finally:
        worker.stop()


def test_a_ticker_that_overran_does_not_burst() -> None:
    """A tick that takes several periods is followed by one tick on the grid, not a burst of the
    ticks it missed (fake clock: each tick advances it)."""
    clock = [0.0]
    ticks: list[float] = []

    def tick(now: float) -> bool:
        ticks.append(now)
        clock[0] += 0.35 if len(ticks) == 2 else 0.001  # the second tick overruns 3.5 periods
        return len(ticks) < 4

    ticker = Ticker("slow", 10.0, tick, clock=lambda: clock[0])

    class NoWait(threading.Event):
        def wait(self, timeout: float | None = None) -> bool:
            clock[0] += timeout or 0.0
            return False

    ticker.run(NoWait(), start_s=0.0)
    assert [round(t, 3) for t in ticks] == [0.0, 0.1, 0.5, 0.6]
    assert ticker.missed == 3
