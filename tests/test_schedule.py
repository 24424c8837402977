"""The schedule leaf: deadlines on a fake clock, rate meter, backoff, the worker's errors."""

from __future__ import annotations

import logging
import threading

import pytest

from poppy_core.errors import ArgumentError
from poppy_core.schedule import Backoff, Periodic, RateMeter, TickGuard, Worker, close_all
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
