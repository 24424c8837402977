"""Random and adversarial documents for the config and move loaders (hypothesis strategies).

Each ``check_*`` feeds one document to a loader and asserts the contract: the loader returns a
valid object or raises a one-line ``PoppyError``, and its memory peak stays small (tracemalloc).
``run_all`` runs every property; ``test_loader_fuzz.py`` runs it in this process and again in a
child process under CPU-time and address-space limits, so a document that hangs or balloons
kills the child instead of the machine (no wall-clock assertion).
"""

from __future__ import annotations

import json
import struct
import tracemalloc
from collections.abc import Callable
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from poppy_core.errors import PoppyError
from poppy_core.motion.move import (
    MAX_FRAMERATE_HZ,
    MAX_POSITION_DEG,
    MAX_VALUES,
    MIN_FRAMERATE_HZ,
    Move,
)
from poppy_core.motion.move_format import MAGIC, decode_any
from poppy_core.robot.config import RobotConfig
from poppy_core.robot.config_io import parse_config_text

PEAK_BYTES = 64 << 20
"""The most a loader may allocate for one of these small documents."""

FUZZ = settings(
    max_examples=settings.default.max_examples,  # 100; ten times as many when thorough
    deadline=None,  # no wall-clock: the child's CPU limit bounds time
    database=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)

VALID = {
    "controllers": {"bus": {"port": "auto", "protocol": 2, "attached_motors": ["arm", "m3"]}},
    "motorgroups": {"arm": ["m1", "m2"]},
    "motors": {
        name: {
            "id": index,
            "type": "XL-320",
            "orientation": "direct",
            "offset": 0.0,
            "angle_limit": [-90.0, 90.0],
        }
        for index, name in enumerate(("m1", "m2", "m3"), start=1)
    },
}

scalars = (
    st.none()
    | st.booleans()
    | st.integers()
    | st.floats()
    | st.text(max_size=12)
    | st.sampled_from(["XL-320", "MX-28", "direct", "indirect", "auto", "m1", "arm"])
)
values = st.recursive(
    scalars,
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4)
    ),
    max_leaves=30,
)


@st.composite
def mutated_configs(draw: st.DrawFn) -> Any:
    """The valid config with a few fields replaced, added or removed."""
    data: Any = json.loads(json.dumps(VALID))
    for _ in range(draw(st.integers(1, 4))):
        node = data
        path = draw(
            st.lists(
                st.sampled_from(
                    [
                        "controllers",
                        "bus",
                        "motorgroups",
                        "arm",
                        "motors",
                        "m1",
                        "m2",
                        "m3",
                        "id",
                        "type",
                        "angle_limit",
                        "orientation",
                        "offset",
                        "protocol",
                        "attached_motors",
                        "pid",
                        "sensors",
                        "profile",
                        "x",
                    ]
                ),
                min_size=1,
                max_size=4,
            )
        )
        for key in path[:-1]:
            child = node.get(key) if isinstance(node, dict) else None
            if not isinstance(child, dict):
                break
            node = child
        if isinstance(node, dict):
            if draw(st.booleans()):
                node[path[-1]] = draw(values)
            else:
                node.pop(path[-1], None)
    return data


def alias_bomb(fanout: int, depth: int) -> str:
    """A YAML "billion laughs": ``fanout ** depth`` values from a few hundred bytes."""
    lines = [f"a0: &a0 [{','.join(['lol'] * fanout)}]"]
    lines += [f"a{i}: &a{i} [{','.join([f'*a{i - 1}'] * fanout)}]" for i in range(1, depth)]
    tail = f"controllers: {{}}\nmotors: {{}}\nsensors: {{s: {{x: *a{depth - 1}}}}}"
    return "\n".join([*lines, tail])


ALIAS_BOMB_ISSUE = alias_bomb(9, 9)
"""The issue's bomb: 9 ** 9 = 387 million strings (4.6 GB and 90 s in `config validate`)."""


def deep(depth: int, kind: str) -> str:
    """A document nested ``depth`` levels deep, in JSON or YAML flow style."""
    if kind == "json-list":
        return "[" * depth + "]" * depth
    if kind == "json-object":
        return '{"a":' * depth + "1" + "}" * depth
    return "a: " + "[" * depth + "]" * depth


adversarial_texts = st.one_of(
    st.builds(alias_bomb, st.integers(2, 12), st.integers(2, 12)),
    st.builds(deep, st.integers(1, 100_000), st.sampled_from(["json-list", "json-object", "yaml"])),
    st.integers(1, 20_000).map(lambda n: '{"motors": {"m1": {"id": ' + "9" * n + "}}}"),
    st.integers(1, 20_000).map(lambda n: "motors: {m1: {id: " + "9" * n + "}}"),
    st.text(max_size=300),
    st.sampled_from(
        [
            "&a [*a]",
            "&a {k: *a}",
            "!!python/object:os.system x",
            "{",
            "[1,",
            "\0",
            "--- !!binary AAAA",
            "? [a]: b",
            "a: !!float nan",
        ]
    ),
)
config_texts = st.one_of(
    adversarial_texts,
    values.map(json.dumps),
    mutated_configs().map(json.dumps),
    mutated_configs().map(lambda d: json.dumps(d).replace('"', "'")),  # YAML flow style
)


def _bounded(run: Callable[[], Any]) -> Any:
    """``run()``'s result (None for a PoppyError), asserting its memory peak."""
    tracemalloc.start()
    try:
        try:
            return run()
        except PoppyError as exc:
            assert "\n" not in str(exc), str(exc)
            return None
    finally:
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        assert peak < PEAK_BYTES, f"{peak:,} bytes"


def check_config_text(text: str) -> None:
    """A config document: a valid RobotConfig, or a one-line ConfigError."""

    def load() -> RobotConfig:
        data = parse_config_text(text, "fuzz.yaml")
        return RobotConfig.from_dict(data, source="fuzz.yaml")

    config = _bounded(load)
    if config is not None:
        assert isinstance(config, RobotConfig)
        json.dumps(config.to_pypot_dict())


def check_config_data(data: Any) -> None:
    """A parsed config: a valid RobotConfig or a ConfigError listing problems one per line."""
    config = _bounded(lambda: RobotConfig.from_dict(data, source="fuzz.json"))
    if config is not None:
        assert isinstance(config, RobotConfig)


# -- moves ----------------------------------------------------------------------------------------

extreme_floats = st.one_of(
    st.floats(),
    st.sampled_from([1e6, 1e-300, 1e308, -1.0, 0.0, MIN_FRAMERATE_HZ, MAX_FRAMERATE_HZ, 50.0]),
)
time_keys = st.one_of(extreme_floats.map(repr), st.sampled_from(["nan", "inf", "-inf", "x", ""]))
frames = st.dictionaries(
    st.sampled_from(["m1", "m2", "m3", ""]),
    st.one_of(extreme_floats, st.lists(extreme_floats | st.none(), max_size=3), values),
    max_size=3,
)


@st.composite
def pypot_moves(draw: st.DrawFn) -> bytes:
    """pypot move JSON, usually well formed, with extreme rates, times and positions."""
    document: Any = {
        "framerate": draw(extreme_floats | values),
        "positions": draw(st.dictionaries(time_keys, frames, max_size=6) | values),
    }
    if draw(st.integers(0, 9)) == 0:
        document = draw(values)
    return json.dumps(document).encode()


@st.composite
def poppy_moves(draw: st.DrawFn) -> bytes:
    """poppy's binary format with a header that may lie about the body."""
    header = {
        "format": draw(st.sampled_from(["poppy-move", "other"])),
        "version": draw(st.sampled_from([1, 2, 0, "1"])),
        "framerate": draw(extreme_floats | values),
        "motors": draw(st.lists(st.sampled_from(["m1", "m2", "m1", ""]), max_size=3) | values),
        "frames": draw(st.integers(-5, 10**15) | values),
        "dtype": draw(st.sampled_from(["<f4", "<f8", ">f4", "x"])),
        "speeds": draw(st.booleans()),
    }
    text = json.dumps(header).encode()
    length = len(text) if draw(st.integers(0, 4)) else draw(st.integers(0, 2**32 - 1))
    body = draw(st.binary(max_size=256))
    return MAGIC + struct.pack("<I", length) + text + body


move_bytes = st.one_of(
    pypot_moves(),
    poppy_moves(),
    st.binary(max_size=300),
    st.integers(1, 100_000).map(
        lambda n: b'{"framerate": 50, "positions": ' + b"[" * n + b"]" * n + b"}"
    ),
)


def check_move_bytes(data: bytes) -> None:
    """A move file: a move within the bounds, or a one-line ConfigError."""
    move = _bounded(lambda: decode_any(data, "fuzz.move"))
    if move is not None:
        assert isinstance(move, Move)
        assert MIN_FRAMERATE_HZ <= move.framerate <= MAX_FRAMERATE_HZ
        assert len(move) * max(len(move.motors), 1) <= MAX_VALUES
        if len(move):
            assert float(abs(move.positions).max()) <= MAX_POSITION_DEG


# -- the properties -------------------------------------------------------------------------------


@FUZZ
@given(config_texts)
def config_text_property(text: str) -> None:
    """Any text given as a config."""
    check_config_text(text)


@FUZZ
@given(st.one_of(mutated_configs(), values))
def config_data_property(data: Any) -> None:
    """Any data given as a parsed config (pypot's ``from_config(dict)``)."""
    check_config_data(data)


@FUZZ
@given(move_bytes)
def move_property(data: bytes) -> None:
    """Any bytes given as a move file."""
    check_move_bytes(data)


PROPERTIES = (config_text_property, config_data_property, move_property)


def run_all() -> None:
    """Run every property (what the resource-limited child process does)."""
    for prop in PROPERTIES:
        prop()
