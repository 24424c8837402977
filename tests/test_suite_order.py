"""The order `make test` hands groups to its workers, and how many workers it starts."""

from __future__ import annotations

import pytest

from tests import conftest
from tests.helpers import timing


def test_a_long_group_handed_out_last_runs_alone_at_the_end() -> None:
    short = [(f"short{k}", [1.0] * 10) for k in range(8)]  # 80 s of many quick tests
    long = ("plugin", [30.0, 30.0])  # two tests of 30 s: fewest tests, handed out last by xdist
    last_end, last = timing.simulate([*short, long], 4)
    first_end, _ = timing.simulate([long, *short], 4)
    assert "plugin" in last.values()
    assert first_end < last_end
    # xdist gives a worker a second group at once when its first has two tests or fewer
    assert (first_end, last_end) == pytest.approx((70.0, 80.0))
    assert timing.simulate([], 4) == (0.0, {})


def test_the_known_slow_groups_go_first_longest_first_then_most_tests_first(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(timing, "SLOW_GROUPS_S", {"slow/b.py": 50.0, "slow/a.py": 90.0})
    counts = {"many.py": 40, "slow/a.py": 1, "few.py": 3, "slow/b.py": 2, "more.py": 40}
    assert timing.handout_order(counts) == [
        "slow/a.py",
        "slow/b.py",
        "many.py",
        "more.py",
        "few.py",
    ]
    assert timing.xdist_order(counts) == ["many.py", "more.py", "few.py", "slow/b.py", "slow/a.py"]


@pytest.mark.parametrize(
    ("average", "runnable", "beside", "workers"),
    [
        (0.2, 0, "", 4),  # idle: two per core (three made the idle run slower)
        (0.5, 2, "2", 4),  # mypy and the OpenGL tests just started beside the run
        (0.5, 4, "", 4),  # four busy loops just started: the average does not see them yet
        (6.0, 0, "2", 4),  # a busy machine
    ],
)
def test_auto_workers_are_two_per_core_idle_or_busy(
    monkeypatch: pytest.MonkeyPatch, average: float, runnable: int, beside: str, workers: int
) -> None:
    monkeypatch.delenv("PYTEST_XDIST_AUTO_NUM_WORKERS", raising=False)
    monkeypatch.setenv("TOGETHER_BESIDE", beside)
    monkeypatch.setattr(conftest.os, "cpu_count", lambda: 2)
    monkeypatch.setattr(conftest.os, "getloadavg", lambda: (average, average, average))
    monkeypatch.setattr(conftest, "runnable_now", lambda: runnable)
    assert conftest.pytest_xdist_auto_num_workers(pytest.Config) == workers  # type: ignore[arg-type]
    monkeypatch.setenv("PYTEST_XDIST_AUTO_NUM_WORKERS", "3")
    assert conftest.pytest_xdist_auto_num_workers(pytest.Config) == 3  # type: ignore[arg-type]
