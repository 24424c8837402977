"""Checks of call arguments (finite, positive, a duration, a rate, a robot's name, one line of
text, a Wi-Fi network and password; a peer's page link): one rule each, ArgumentError; and
seconds read from an environment variable (ConfigError)."""

from __future__ import annotations

import math
import os
import re
import unicodedata
from collections.abc import Callable, Iterable
from numbers import Real
from typing import Any, Generic, TypeVar, cast, overload
from urllib.parse import urlsplit

from poppy_core.errors import ArgumentError, ConfigError

# A loop never runs faster than this, whatever it is asked: a period under a millisecond would
# spin a core (the sync loops of a real bus run at 50-100 Hz, a servo cannot follow faster).
MAX_RATE_HZ = 1000.0
# A loop asked to run slower than once a day is a mistake, not a schedule.
MIN_RATE_HZ = 1.0 / (24 * 3600.0)
# The longest duration any motion, recording or wait takes (a day).
MAX_DURATION_S = 24 * 3600.0
# The shortest non-zero duration: below it a trajectory's polynomial divides by an underflowed
# zero (1e-300 ** 3), and no loop ticks that fast anyway (``1 / MAX_RATE_HZ``).
MIN_DURATION_S = 1.0 / MAX_RATE_HZ
# The largest magnitude a physical value (degrees, metres, %, a speed factor) may have: far
# beyond any robot's, small enough that every arithmetic on it stays finite.
MAX_MAGNITUDE = 1e9


def _describe(field: str) -> str:
    return field or "value"


def number(value: object, field: str = "") -> float:
    """``value`` as a finite float; refuses NaN, infinities, huge values, booleans and text."""
    kind = type(value)  # float and int first: the ABC check costs more than the rest (hot path)
    if (
        kind is not float
        and kind is not int
        and (isinstance(value, bool) or not isinstance(value, Real))
    ):
        raise ArgumentError(
            f"{_describe(field)} must be a number, got {value!r}", field=field, value=value
        )
    try:
        result = float(cast(Real, value))  # a Real: checked above
    except (OverflowError, ValueError) as exc:
        raise ArgumentError(
            f"{_describe(field)} must be a finite number, got a number too large",
            field=field,
            value=value,
        ) from exc
    if not math.isfinite(result):
        raise ArgumentError(
            f"{_describe(field)} must be a finite number, got {result}", field=field, value=value
        )
    if abs(result) > MAX_MAGNITUDE:
        raise ArgumentError(
            f"{_describe(field)} must be within ±{MAX_MAGNITUDE:g}, got {result:g}",
            field=field,
            value=value,
        )
    return result


def number_from(value: object, field: str = "") -> float:
    """Like ``number``, also taking text (a URL segment, a command-line or JSON string).

    Text is read as a decimal number (``"0.5"``, ``"-3"``, ``"1e3"``), never evaluated; an
    integer too large for a float is refused like any other huge value.
    """
    if isinstance(value, str):
        text = value.strip()
        try:
            parsed: float = float(text)
        except ValueError:
            shown = text if len(text) <= 40 else text[:40] + "..."
            raise ArgumentError(
                f"{_describe(field)} must be a number, got {shown!r}", field=field, value=value
            ) from None
        return number(parsed, field)
    return number(value, field)


def positive(value: object, field: str = "") -> float:
    """A finite number > 0."""
    result = number(value, field)
    if result <= 0:
        raise ArgumentError(
            f"{_describe(field)} must be greater than 0, got {result:g}", field=field, value=value
        )
    return result


def non_negative(value: object, field: str = "") -> float:
    """A finite number ≥ 0."""
    result = number(value, field)
    if result < 0:
        raise ArgumentError(
            f"{_describe(field)} must be 0 or more, got {result:g}", field=field, value=value
        )
    return result


def in_range(value: object, low: float, high: float, field: str = "", unit: str = "") -> float:
    """A finite number within [low, high]."""
    result = number(value, field)
    if not low <= result <= high:
        suffix = f" {unit}" if unit else ""
        raise ArgumentError(
            f"{_describe(field)} must be {low:g}-{high:g}{suffix}, got {result:g}{suffix}",
            field=field,
            value=value,
        )
    return result


def seconds_from_env(
    name: str, default: float, *, high: float, zero: bool, what: str, example: str, unset: str
) -> float:
    """Seconds from the environment variable ``name`` (read at each call): ``default`` when it is
    unset or blank, else a number from 0 (``zero``) or above 0, at most ``high``.

    Raises:
        ConfigError: in one line, ``NAME='TEXT' is not WHAT: give seconds ... (e.g. EXAMPLE), or
            unset it for UNSET`` (text, nan, infinities and numbers out of range alike).
    """
    text = os.environ.get(name, "").strip()
    if not text:
        return default
    try:
        value = float(text)
    except ValueError:
        value = math.nan  # refused below, as nan is
    low_ok = value >= 0.0 if zero else value > 0.0
    if not (low_ok and value <= high):
        span = f"from 0 to {high:g}" if zero else f"above 0, at most {high:g}"
        raise ConfigError(
            f"{name}={text!r} is not {what}: give seconds {span} (e.g. {example}), "
            f"or unset it for {unset}"
        )
    return value


def duration(value: object, field: str = "duration", *, allow_zero: bool = True) -> float:
    """Seconds: 0 (at once; refused without ``allow_zero``) or ``MIN_DURATION_S`` up to a day."""
    result = in_range(value, 0.0, MAX_DURATION_S, field, "s")
    if not allow_zero and result <= 0:
        raise ArgumentError(f"{field} must be greater than 0 s, got {result:g} s", field=field)
    if 0 < result < MIN_DURATION_S:
        raise ArgumentError(
            f"{field} must be 0 (at once) or at least {MIN_DURATION_S:g} s, got {result:g} s",
            field=field,
            value=value,
        )
    return result


def rate(value: object, field: str = "rate") -> float:
    """A loop frequency in Hz: once a day up to ``MAX_RATE_HZ``."""
    return in_range(value, MIN_RATE_HZ, MAX_RATE_HZ, field, "Hz")


def period(value: object, field: str = "period") -> float:
    """A loop period in seconds: ``1 / MAX_RATE_HZ`` up to a day."""
    return in_range(value, 1.0 / MAX_RATE_HZ, 1.0 / MIN_RATE_HZ, field, "s")


def count(value: object, low: int, high: int, field: str = "") -> int:
    """An integer within [low, high], checked before anything is allocated from it."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise ArgumentError(
            f"{_describe(field)} must be a whole number, got {value!r}", field=field, value=value
        )
    if not low <= value <= high:
        raise ArgumentError(
            f"{_describe(field)} must be {low}-{high}, got {value}", field=field, value=value
        )
    return value


ROBOT_NAME = re.compile(r"[a-z0-9](?:[a-z0-9-]{0,61}[a-z0-9])?")
"""A robot's name: one DNS label, lower case (its mDNS name ``NAME.local``, its Zenoh key
``poppy/NAME``, its ROS 2 node)."""


def robot_name(value: object, field: str = "name") -> str:
    """``value`` as a robot's name: ``Poppy``, ``poppy.local`` -> ``poppy``.

    One rule for every place a robot is named (``poppy serve --name``, mDNS, Zenoh, the
    settings page, ``zenoh:NAME``): a DNS label (letters, digits and inner hyphens, at most
    63), so that ``NAME.local`` and ``poppy/NAME`` name the same robot. DNS names ignore case,
    so the name is lower-cased; a ``.local`` suffix (mDNS's domain) is dropped.

    Raises:
        ArgumentError: (a ValueError) any other name, with ``field`` and the rule named.
    """
    text = value if isinstance(value, str) else ""
    name = text.strip().lower().rstrip(".").removesuffix(".local")
    if not ROBOT_NAME.fullmatch(name):
        raise ArgumentError(
            f"{_describe(field)} {value!r} is not a robot name: give 1-63 letters, digits and "
            "hyphens, not starting or ending with a hyphen (no '_', '.' or space: it is the "
            "robot's NAME.local), e.g. poppy or ergo-2",
            field=field,
            value=value,
        )
    return name


def robot_name_of_host(hostname: str) -> str:
    """A machine's robot name: its first label lower-cased, other characters as ``-``
    (``My_Pi.lan`` -> ``my-pi``), ``poppy`` when nothing is left (the default of ``--name``)."""
    label = hostname.split(".")[0].lower()
    name = re.sub(r"[^a-z0-9-]", "-", label)[:63].strip("-")
    return name or "poppy"


def _shown(text: str) -> str:
    return repr(text if len(text) <= 40 else text[:40] + "...")


def one_line(value: object, field: str = "") -> str:
    """``value`` as text without a control character (a newline, a tab, a NUL, DEL...): a
    value written into a file of lines (a systemd unit) or handed to another program."""
    if not isinstance(value, str):
        raise ArgumentError(
            f"{_describe(field)} must be text, got {value!r}", field=field, value=value
        )
    if any(unicodedata.category(c) == "Cc" for c in value):
        raise ArgumentError(
            f"{_describe(field)} {_shown(value)} holds a control character (a newline, tab or "
            "NUL): give it on one line of visible characters",
            field=field,
            value=value,
        )
    return value


MIN_PSK = 8
MAX_PSK = 63
MAX_SSID_BYTES = 32
_HEX_PSK = re.compile(r"[0-9a-fA-F]{64}")


def wifi_password(value: object, field: str = "password") -> str:
    """A WPA password: 8-63 printable ASCII characters (space to ``~``), or a 64-hex-digit
    key (IEEE 802.11i's two forms of a pre-shared key)."""
    text = value if isinstance(value, str) else ""
    if _HEX_PSK.fullmatch(text) or (
        MIN_PSK <= len(text) <= MAX_PSK and all(" " <= c <= "~" for c in text)
    ):
        return text
    raise ArgumentError(
        f"{_describe(field)} is not a WPA password: give {MIN_PSK}-{MAX_PSK} printable ASCII "
        "characters (letters, digits, punctuation, space; no accent or control character) "
        "or a 64-hex-digit key",
        field=field,
    )


def wifi_ssid(value: object, field: str = "ssid") -> str:
    """A Wi-Fi network's name: 1-32 bytes (UTF-8), no control character, not starting with
    ``-`` (nmcli would read it as an option)."""
    text = one_line(value, field)
    if not 1 <= len(text.encode()) <= MAX_SSID_BYTES or text.startswith("-"):
        raise ArgumentError(
            f"{_describe(field)} {_shown(text)} is not a Wi-Fi network name: give 1-"
            f"{MAX_SSID_BYTES} bytes, not starting with '-'",
            field=field,
            value=value,
        )
    return text


UNSPECIFIED_HOSTS = frozenset({"0.0.0.0", "::", ""})
"""Bind-all addresses: in a browser they mean the viewer's own machine, never a peer."""


def peer_page(page: object, hosts: Iterable[str]) -> str | None:
    """A peer robot's ``page`` URL as a link, or None: only ``http(s)`` to one of ``hosts``, the
    peer's own announced addresses (its Zenoh endpoints' hosts, ``NAME.local``).

    What a peer describes is anyone's text on the network: a ``javascript:`` URL or a link to
    another site (a page asking for the robot's token) is not shown as a link.
    """
    if not isinstance(page, str) or len(page) > 2048 or any(c.isspace() for c in page):
        return None
    try:
        parts = urlsplit(page)
        host = (parts.hostname or "").lower()
        parts.port  # noqa: B018 (a bad port raises here)
    except ValueError:
        return None
    allowed = {h.lower().strip("[]") for h in hosts} - UNSPECIFIED_HOSTS
    if parts.scheme not in ("http", "https") or parts.username or parts.password:
        return None
    return page if host in allowed and host not in UNSPECIFIED_HOSTS else None


T = TypeVar("T")


class Checked(Generic[T]):
    """An attribute whose every assignment goes through ``rule(value, name)``, the attribute's
    name naming the field of the error: ``bpm = Checked(non_negative, "Beats per minute.")``.

    The value is kept in ``_<name>`` of the instance; reading it before the first assignment
    raises AttributeError, as a property over an unset attribute would.
    """

    def __init__(self, rule: Callable[[Any, str], T], doc: str = "") -> None:
        self._rule = rule
        self.__doc__ = doc
        self._name = self._slot = ""

    def __set_name__(self, owner: type, name: str) -> None:
        self._name, self._slot = name, f"_{name}"

    @overload
    def __get__(self, obj: None, owner: type | None = None) -> Checked[T]: ...

    @overload
    def __get__(self, obj: object, owner: type | None = None) -> T: ...

    def __get__(self, obj: object | None, owner: type | None = None) -> Checked[T] | T:
        if obj is None:
            return self
        value: T = getattr(obj, self._slot)
        return value

    def __set__(self, obj: object, value: Any) -> None:
        setattr(obj, self._slot, self._rule(value, self._name))
