"""Model lookups, aliases, default tables and the shape of every control table."""

from __future__ import annotations

import itertools

import pytest

from poppy_core.errors import ProtocolError, RegisterError, UnknownModelError
from poppy_core.models import (
    ALL_MODELS,
    AX_12A,
    COMMON_NAMES,
    MX_12W,
    MX_28,
    STANDARD_BAUDRATES,
    XL330_M288,
    XL430_W250,
    XL_320,
    XM430_W350,
    ServoModel,
    model_by_name,
    model_by_number,
    standard_baudrates,
)

EXPECTED_NUMBERS = {
    "AX-12A": 12,
    "AX-18A": 18,
    "MX-12W": 360,
    "MX-28": 29,
    "MX-64": 310,
    "MX-106": 320,
    "XL-320": 350,
    "XL430-W250": 1060,
    "XM430-W350": 1020,
    "XL330-M288": 1200,
}


def test_all_models_listed_with_their_numbers() -> None:
    assert {model.name: model.model_number for model in ALL_MODELS} == EXPECTED_NUMBERS
    for name, number in EXPECTED_NUMBERS.items():
        model = model_by_number(number)
        assert model is not None and model.name == name


@pytest.mark.parametrize("number", [0, 1, 30, 311, 104 + 1, 1190, 65535, -1])
def test_unknown_model_numbers_give_none(number: int) -> None:
    assert model_by_number(number) is None


def test_mx12w_also_known_by_the_emanual_number() -> None:
    assert model_by_number(104) is MX_12W


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("AX-12A", AX_12A),
        ("ax-12a", AX_12A),
        ("AX-12", AX_12A),
        ("AX12A", AX_12A),
        ("AX-12+", AX_12A),
        ("XL320", XL_320),
        ("xl-320", XL_320),
        ("MX-28AT", MX_28),
        ("MX-28R", MX_28),
        ("mx28", MX_28),
        ("MX-12", MX_12W),
        ("XL430-W250-T", XL430_W250),
        ("xm430 w350", XM430_W350),
        ("XL330-M288-T", XL330_M288),
    ],
)
def test_model_by_name_variants(name: str, expected: ServoModel) -> None:
    assert model_by_name(name) is expected


@pytest.mark.parametrize("name", ["AX-12W", "MX-28(2.0)", "XL-430", "", "dynamixel"])
def test_model_by_name_unknown(name: str) -> None:
    with pytest.raises(UnknownModelError):
        model_by_name(name)


@pytest.mark.parametrize("model", ALL_MODELS, ids=lambda m: m.name)
def test_common_names_resolve(model: ServoModel) -> None:
    for name in COMMON_NAMES:
        assert model.has_register(name), name
        assert model.register(name).name in model.registers
    if model.has_torque_limit:
        assert model.register("torque_limit").name == "torque_limit"
    else:
        assert not model.has_register("torque_limit")


def test_aliases_pick_the_closest_register() -> None:
    assert AX_12A.register("min_position_limit").name == "cw_angle_limit"
    assert AX_12A.register("max_position_limit").name == "ccw_angle_limit"
    assert AX_12A.register("max_temperature").name == "temperature_limit"
    assert XL430_W250.register("present_speed").name == "present_velocity"
    assert XL430_W250.register("moving_speed").name == "profile_velocity"
    assert XL430_W250.register("present_load").name == "present_load"
    assert XM430_W350.register("present_load").name == "present_current"
    assert XM430_W350.register("present_voltage").name == "present_input_voltage"
    assert XL_320.register("registered_instruction").name == "registered"


def test_unknown_register_lists_close_names() -> None:
    with pytest.raises(RegisterError, match="goal_position") as info:
        MX_28.register("goal_positon")
    assert info.value.register == "goal_positon"
    with pytest.raises(RegisterError, match="MX-28"):
        MX_28.register("operating_mode")


@pytest.mark.parametrize("model", ALL_MODELS, ids=lambda m: m.name)
def test_default_table(model: ServoModel) -> None:
    table = model.default_table()
    assert isinstance(table, bytearray)
    assert len(table) == model.table_size
    assert int.from_bytes(table[0:2], "little") == model.model_number
    id_reg = model.register("id")
    assert table[id_reg.address] == 1
    baud = model.register("baudrate")
    assert model.baudrate_bps(table[baud.address]) in STANDARD_BAUDRATES[model.protocol]
    srl = model.register("status_return_level")
    assert table[srl.address] == 2
    assert model.default_table() is not table  # a fresh copy each time


@pytest.mark.parametrize("model", ALL_MODELS, ids=lambda m: m.name)
def test_tables_are_consistent(model: ServoModel) -> None:
    ram_start = 24 if model.protocol == 1 or model is XL_320 else 64
    spans: list[tuple[int, int, str]] = []
    for name, reg in model.registers.items():
        assert reg.name == name
        assert reg.size in (1, 2, 4)
        assert reg.access in ("R", "RW")
        assert reg.memory == ("EEPROM" if reg.address < ram_start else "RAM")
        assert reg.min_raw <= reg.max_raw
        assert reg.signed == (reg.min_raw < 0)
        bits = 8 * reg.size
        low, high = (
            (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if reg.signed else (0, (1 << bits) - 1)
        )
        assert low <= reg.min_raw and reg.max_raw <= high, name
        if reg.default is not None:
            assert reg.min_raw <= reg.default <= reg.max_raw, name
        assert reg.unit == reg.conversion.unit
        spans.append((reg.address, reg.address + reg.size, name))
    spans.sort()
    for (_, end, name), (start, _, following) in itertools.pairwise(spans):
        assert end <= start, f"{name} overlaps {following}"


def test_register_at() -> None:
    reg = AX_12A.register_at(30)
    assert reg is not None and reg.name == "goal_position"
    assert AX_12A.register_at(31) is None


def test_models_are_immutable() -> None:
    with pytest.raises(TypeError):
        AX_12A.registers["x"] = AX_12A.register("id")  # type: ignore[index]
    with pytest.raises(AttributeError):
        AX_12A.name = "AX-99"  # type: ignore[misc]


def test_model_facts() -> None:
    assert AX_12A.position_range_deg == 300.0 and AX_12A.resolution == 1024
    assert MX_28.position_range_deg == 360.0 and MX_28.resolution == 4096
    assert AX_12A.no_load_speed_dps == pytest.approx(59 * 6)
    assert MX_28.stall_torque_nm == pytest.approx(2.5)
    assert XL430_W250.protocol == 2 and AX_12A.protocol == 1 and XL_320.protocol == 2
    assert AX_12A.has_torque_limit and not XM430_W350.has_torque_limit
    assert dict(XL_320.baudrates) == {0: 9_600, 1: 57_600, 2: 115_200, 3: 1_000_000}


def test_standard_baudrates() -> None:
    assert standard_baudrates(1) == STANDARD_BAUDRATES[1]
    assert 57_600 in standard_baudrates(1)
    assert standard_baudrates(2)[-1] == 4_500_000
    with pytest.raises(ProtocolError):
        standard_baudrates(3)


@pytest.mark.parametrize("bps", STANDARD_BAUDRATES[1])
def test_protocol1_standard_rates_map_to_codes(bps: int) -> None:
    for model in ALL_MODELS:
        if model.protocol == 1:
            assert model.baudrate_bps(model.baudrate_code(bps)) == bps


def test_find_register_resolves_aliases_and_returns_none_for_unknown_names() -> None:
    from poppy_core.models import model_by_name

    mx = model_by_name("MX-28")
    assert mx.find_register("min_position_limit") is mx.register("cw_angle_limit")
    assert mx.find_register("goal_velocity") is None  # an X-series name: no error, no search
    xl = model_by_name("XL430-W250")
    assert xl.find_register("present_speed") is xl.register("present_velocity")
