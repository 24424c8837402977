"""The guided setup's core flow: a lost rate change says how to go on, and going on finishes."""

from __future__ import annotations

from typing import Any

import pytest

from poppy_core.bus import DxlBus
from poppy_core.emulator import build_bus_from_spec, serve_link
from poppy_core.errors import SetupError
from poppy_core.models import ServoModel, SIValue
from poppy_core.robot.guided_setup import GuidedSetup, motor_targets
from poppy_core.robot.profiles import load_profile

ERGO_JR = load_profile("ergo-jr")


class QuirkyBus(DxlBus):
    """A bus whose baud-rate writes land on another rate (a firmware surprise, a bad cable)."""

    def write_register(self, id: int, model: ServoModel, name: str, value: SIValue) -> None:
        super().write_register(id, model, name, 115_200 if name == "baudrate" else value)


class QuirkySetup(GuidedSetup):
    def _bus(self, rate: int, protocol: int) -> DxlBus:
        return QuirkyBus(self.port, rate, protocol, retries=2, min_timeout_s=0.1)


def test_a_lost_rate_change_says_where_the_motor_is_and_the_setup_again_finds_it() -> None:
    virtual = build_bus_from_spec("XL-320:1", protocol=2, baudrate=57_600)
    with serve_link(virtual) as server:
        (m3,) = motor_targets(ERGO_JR, ["m3"])
        with pytest.raises(SetupError) as caught:
            QuirkySetup(ERGO_JR, server.url, ["m3"]).set_up(m3)
        message = str(caught.value)
        assert message.startswith("m3: motor 3 does not answer at 1000000 bps")
        assert "it answers at 115200 bps" in message
        assert "running the setup again for m3 finds it at any ID and rate" in message
        assert virtual.motors[0].baudrate_bps == 115_200
        outcome = GuidedSetup(ERGO_JR, server.url, ["m3"]).set_up(m3)
    assert (outcome.found.id, outcome.found.baudrate) == (3, 115_200)
    assert outcome.changes["baudrate"] == (115_200, 1_000_000)
    assert virtual.motors[0].baudrate_bps == 1_000_000 and virtual.motors[0].id == 3


def test_only_names_motors_of_the_profile() -> None:
    with pytest.raises(SetupError, match=r"no motor m9 in this profile \(motors: m1, m2"):
        motor_targets(ERGO_JR, ["m3", "m9"])


def test_targets_keep_the_limits_the_registers_can_hold() -> None:
    m1 = motor_targets(ERGO_JR, ["m1"])[0]
    assert m1.angle_limits == (-150.0, pytest.approx(149.707, abs=0.001))
    assert (m1.id, m1.model, m1.baudrate, m1.protocol, m1.return_delay_us) == (
        1,
        "XL-320",
        1_000_000,
        2,
        0.0,
    )


def test_a_protocol_1_kit_motor_is_found_at_its_factory_rate_and_set_up() -> None:
    torso = load_profile("torso")
    virtual = build_bus_from_spec("MX-28:1", protocol=1, baudrate=57_600)
    with serve_link(virtual) as server:
        flow = GuidedSetup(torso, server.url)
        target = flow.targets[0]
        outcome = flow.set_up(target)
    assert (outcome.found.id, outcome.found.baudrate, outcome.found.protocol) == (1, 57_600, 1)
    assert outcome.next_motor == flow.targets[1].name
    motor = virtual.motors[0]
    assert (motor.id, motor.baudrate_bps) == (target.id, target.baudrate)
    assert motor.table.get_si("min_position_limit") == pytest.approx(
        target.angle_limits[0], abs=0.1
    )


def test_a_protocol_1_search_is_patient_at_the_profile_s_rate_only(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # each empty rate tried one by one would pay the scan's patient look (1-2 s each)
    import poppy_core.robot.guided_setup as guided

    calls: list[tuple[list[int], bool]] = []
    real = guided.scan

    def spy(*args: Any, **kwargs: Any) -> Any:
        calls.append((list(args[1] or []), kwargs.get("patient", True)))
        return real(*args, **kwargs)

    monkeypatch.setattr(guided, "scan", spy)
    torso = load_profile("torso")
    # the third rate searched (after the profile's and the factory's): the fewest scans that
    # show the rates after the first are not patient (each rate scanned costs 1-2 s)
    virtual = build_bus_from_spec("MX-28:1", protocol=1, baudrate=500_000)
    with serve_link(virtual) as server:
        flow = GuidedSetup(torso, server.url)
        found = flow.find_single(flow.targets[0])
    assert (found.id, found.baudrate) == (1, 500_000)
    assert calls[0] == ([flow.targets[0].baudrate], True)  # the profile's rate, patient
    assert len(calls) >= 3 and all(not patient for _, patient in calls[1:])


def test_a_wrong_model_of_protocol_1_is_named_after_the_first_rate_it_answers_at(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # each protocol 1 rate costs a scan of the 254 IDs (1-2 s): the other rates are not tried
    import poppy_core.robot.guided_setup as guided

    calls: list[tuple[list[int] | None, list[int]]] = []
    real = guided.scan

    def spy(*args: Any, **kwargs: Any) -> Any:
        calls.append((None if args[1] is None else list(args[1]), list(args[2])))
        return real(*args, **kwargs)

    monkeypatch.setattr(guided, "scan", spy)
    virtual = build_bus_from_spec("MX-28:1", protocol=1, baudrate=1_000_000)
    with serve_link(virtual) as server:
        flow = GuidedSetup(ERGO_JR, server.url, ["m1"])
        with pytest.raises(SetupError, match="found an MX-28 at ID 1 at 1000000 bps, protocol 1"):
            flow.find_single(flow.targets[0])
    assert [protocols for _, protocols in calls] == [[2], [1]]
    assert calls[1][0] == [1_000_000]  # the profile's rate, where it answers
