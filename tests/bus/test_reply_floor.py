"""POPPY_REPLY_FLOOR_S: the first-reply floor of motors known to be there, for emulators and
bridges the OS runs late (the test suite's `poppy` commands on a busy machine)."""

from __future__ import annotations

import pytest

from poppy_core.bus import DxlBus
from poppy_core.bus.scan import scan
from poppy_core.bus.timing import MIN_REPLY_TIMEOUT_S, REPLY_FLOOR_ENV, reply_floor_s
from poppy_core.errors import ConfigError
from poppy_core.models import MX_28
from tests.helpers.bus import Emulate
from tests.helpers.cli import run_poppy

MX_PRESENT = MX_28.registers["present_position"].address


def test_unset_the_floor_is_a_real_adapters(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(REPLY_FLOOR_ENV, raising=False)
    assert reply_floor_s() == MIN_REPLY_TIMEOUT_S == 0.010
    monkeypatch.setenv(REPLY_FLOOR_ENV, "  ")
    assert reply_floor_s() == MIN_REPLY_TIMEOUT_S


def test_the_variable_sets_a_new_buses_floor(
    emulate: Emulate, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv(REPLY_FLOOR_ENV, "0.75")
    with emulate("MX-28:4") as (_, url):
        with DxlBus(url) as bus:
            assert bus.min_timeout_s == 0.75
        with DxlBus(url, min_timeout_s=0.02) as bus:  # a floor the code gives is kept
            assert bus.min_timeout_s == 0.02


def test_a_late_emulator_answers_within_the_raised_floor(
    emulate: Emulate, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Replies 50 ms late (an emulator thread a busy machine ran late): silence at the
    adapter's 10 ms floor, a motor there with the floor raised."""
    monkeypatch.delenv(REPLY_FLOOR_ENV, raising=False)
    with emulate("MX-28:4", via="pty") as (virtual, url):
        virtual.extra_delay_s = 0.05
        with DxlBus(url, retries=0) as bus:
            assert bus.ping(4) is None
        monkeypatch.setenv(REPLY_FLOOR_ENV, "5")
        with DxlBus(url, retries=0) as bus:
            assert bus.ping(4) is not None
            assert len(bus.read(4, MX_PRESENT, 2)) == 2
            assert bus.stats.timeouts == 0


def test_a_scan_keeps_no_floor(emulate: Emulate, monkeypatch: pytest.MonkeyPatch) -> None:
    """A scan asks mostly absent IDs: the variable does not make it wait for each."""
    monkeypatch.setenv(REPLY_FLOOR_ENV, "30")
    with emulate("MX-28:4", via="pty") as (_, url):
        found = scan([url], baudrates=[1_000_000], protocols=[1], ids=range(1, 8))
    assert [motor.id for motor in found] == [4]


@pytest.mark.parametrize("value", ["fast", "-0.1", "nan", "1e9", "inf"])
def test_a_bad_value_is_one_clear_line(
    value: str, emulate: Emulate, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv(REPLY_FLOOR_ENV, value)
    with pytest.raises(ConfigError, match=rf"^{REPLY_FLOOR_ENV}=.* give seconds from 0 to 60"):
        reply_floor_s()
    with emulate("MX-28:4", via="pty") as (_, url):
        result = run_poppy(
            "motor",
            "get",
            "4",
            "present_position",
            "--port",
            url,
            "--baud",
            "1000000",
            "--protocol",
            "1",
            env={REPLY_FLOOR_ENV: value},
        )
    assert result.code == 1
    [line] = result.stderr.strip().splitlines()
    assert REPLY_FLOOR_ENV in line and "seconds" in line and "Traceback" not in result.stderr
