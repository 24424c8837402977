"""The argument checks leaf: one rule per kind of argument, one ArgumentError each."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from poppy_core import checks
from poppy_core.errors import ArgumentError, ConfigError

BAD_NUMBERS = [math.nan, math.inf, -math.inf, 10**400, 1e300, "12", None, True, [1]]


@pytest.mark.parametrize("value", BAD_NUMBERS, ids=repr)
def test_number_refuses_what_is_not_a_finite_physical_number(value: object) -> None:
    with pytest.raises(ArgumentError, match="speed"):
        checks.number(value, "speed")


def test_number_takes_numpy_and_ints() -> None:
    assert checks.number(np.float32(1.5)) == 1.5
    assert checks.number(3) == 3.0


@pytest.mark.parametrize(
    ("check", "value"),
    [
        (checks.positive, 0),
        (checks.positive, -1),
        (checks.non_negative, -1e-9),
        (checks.duration, -1),
        (checks.duration, 1e6),
        (checks.rate, 1e-300),
        (checks.rate, 0),
        (checks.rate, 1e308),
        (checks.period, 1e-300),
    ],
)
def test_range_checks_refuse_with_the_field_named(check, value) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ArgumentError, match=r"^f must") as info:
        check(value, "f")
    assert info.value.field == "f"


def test_duration_without_zero() -> None:
    assert checks.duration(0) == 0
    with pytest.raises(ArgumentError):
        checks.duration(0, allow_zero=False)


def test_count_checks_before_anything_is_made() -> None:
    assert checks.count(5, 0, 253) == 5
    for bad in (10**20, -1, 2.0, True):
        with pytest.raises(ArgumentError):
            checks.count(bad, 0, 253, "id")


@given(st.floats(allow_nan=True, allow_infinity=True))
def test_number_is_finite_or_refused(value: float) -> None:
    try:
        result = checks.number(value)
    except ArgumentError:
        assert not math.isfinite(value) or abs(value) > checks.MAX_MAGNITUDE
    else:
        assert math.isfinite(result) and result == value


def test_number_from_reads_text_and_refuses_what_is_not_a_finite_number() -> None:
    assert checks.number_from(" 0.5 ", "x") == 0.5
    assert checks.number_from(-3, "x") == -3.0
    for text in ("abc", "nan", "inf", "1e309", "9" * 400, "", "0x10"):
        with pytest.raises(ArgumentError, match="speed"):
            checks.number_from(text, "speed")


def test_a_duration_is_zero_or_long_enough_to_divide_by() -> None:
    assert checks.duration(checks.MIN_DURATION_S) == checks.MIN_DURATION_S
    for tiny in (1e-300, 5e-324, 1e-7):
        with pytest.raises(ArgumentError, match="at least"):
            checks.duration(tiny)


def test_a_checked_attribute_refuses_through_its_rule_and_names_itself() -> None:
    from poppy_core.checks import Checked, non_negative

    class Knob:
        gain = Checked(non_negative, "How much (>= 0).")

        def __init__(self) -> None:
            self.gain = 2

    knob = Knob()
    assert knob.gain == 2.0 and isinstance(knob.gain, float)
    with pytest.raises(ArgumentError) as refused:
        knob.gain = -1.0
    assert refused.value.field == "gain" and knob.gain == 2.0
    assert Knob.gain.__doc__ == "How much (>= 0)."


@pytest.mark.parametrize(
    ("given", "name"),
    [("poppy", "poppy"), ("Ergo-2", "ergo-2"), ("POPPY.local.", "poppy"), (" jr1 ", "jr1")],
)
def test_a_robot_name_is_one_lower_case_dns_label(given: str, name: str) -> None:
    assert checks.robot_name(given) == name


@pytest.mark.parametrize(
    "given", ["", "jr_01", "jr.1", "poppy.example", "-jr", "jr-", "a b", "a/b", "a" * 64, None, 3]
)
def test_a_robot_name_refused_names_the_field_the_rule_and_an_example(given: object) -> None:
    with pytest.raises(ArgumentError) as refused:
        checks.robot_name(given, "--name")
    message = str(refused.value)
    assert message.startswith(f"--name {given!r} is not a robot name: ")
    assert "e.g. poppy or ergo-2" in message and "\n" not in message
    assert refused.value.field == "--name"


@pytest.mark.parametrize(
    "password",
    ["password1", "a b~c!d{e}", "x" * 63, "0123456789abcdef" * 4, "ABCDEF0123456789" * 4],
)
def test_wpa_passwords_are_printable_ascii_or_64_hex(password: str) -> None:
    assert checks.wifi_password(password) == password


@pytest.mark.parametrize(
    "password",
    [
        "short1",
        "x" * 64,
        "g" * 64,
        "pass\x00word1",
        "pass\tword1",
        "pässwörd12",
        "pass\x7fword",
        None,
    ],
)
def test_other_wpa_passwords_are_refused_in_one_line(password: object) -> None:
    with pytest.raises(ArgumentError, match="not a WPA password") as caught:
        checks.wifi_password(password, "password")
    assert "\n" not in str(caught.value)
    assert not isinstance(password, str) or password not in str(caught.value)  # a secret


@pytest.mark.parametrize("ssid", ["", "-ask", "--", "é" * 17, "a\nb", "a\x00b", "x" * 33])
def test_bad_ssids_are_refused(ssid: str) -> None:
    with pytest.raises(ArgumentError):
        checks.wifi_ssid(ssid)


def test_ssids_of_up_to_32_bytes_are_taken() -> None:
    assert checks.wifi_ssid("é" * 16) == "é" * 16
    assert checks.wifi_ssid("Class:room a-b") == "Class:room a-b"


@pytest.mark.parametrize("text", ["a\nb", "a\rb", "a\x00", "\x1b[2J", "a\x85b", 3])
def test_one_line_refuses_control_characters(text: object) -> None:
    with pytest.raises(ArgumentError) as caught:
        checks.one_line(text, "--port")
    assert str(caught.value).startswith("--port ") and "\n" not in str(caught.value)


ENV_NAME = "POPPY_TEST_SECONDS"
# what an environment variable can hold (no NUL, no lone surrogate)
ENV_CHARACTERS = st.characters(blacklist_categories=("Cs",), blacklist_characters="\x00")


def env_seconds(zero: bool) -> float:
    return checks.seconds_from_env(
        ENV_NAME, 2.0, high=60.0, zero=zero, what="a wait", example="5", unset="2 s"
    )


@given(st.floats(min_value=0.0, max_value=60.0), st.booleans())
def test_seconds_from_env_in_range_are_read_back(seconds: float, zero: bool) -> None:
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv(ENV_NAME, f" {seconds!r} ")
        if seconds == 0.0 and not zero:
            with pytest.raises(ConfigError, match="give seconds above 0, at most 60 "):
                env_seconds(zero)
        else:
            assert env_seconds(zero) == seconds


@given(
    st.one_of(
        st.floats(allow_nan=True).filter(lambda v: not 0.0 <= v <= 60.0).map(repr),
        st.text(alphabet=ENV_CHARACTERS).filter(lambda t: t.strip() and not _is_number(t)),
    ),
    st.booleans(),
)
def test_seconds_from_env_refuses_the_rest_in_one_line(text: str, zero: bool) -> None:
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv(ENV_NAME, text)
        with pytest.raises(ConfigError) as refused:
            env_seconds(zero)
    message = str(refused.value)
    assert message.startswith(f"{ENV_NAME}=") and "or unset it for 2 s" in message
    assert "\n" not in message


def test_seconds_from_env_unset_or_blank_is_the_default(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(ENV_NAME, raising=False)
    assert env_seconds(True) == 2.0
    monkeypatch.setenv(ENV_NAME, "   ")
    assert env_seconds(False) == 2.0


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True
