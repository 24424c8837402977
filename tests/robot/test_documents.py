"""Hostile documents: alias bombs, deep nesting, huge numbers, special files: one-line errors."""

from __future__ import annotations

import os
import tracemalloc
from pathlib import Path
from typing import Any

import pytest

from poppy_core.documents import CONFIG_LIMITS, Limits, check_shape, parse_json, parse_yaml
from poppy_core.errors import ConfigError
from poppy_core.robot import load_config

# The classic "billion laughs": 9 levels of 9 aliases, 9**9 = 387 million strings once expanded.
ALIAS_BOMB = (
    "\n".join(
        [f"a0: &a0 [{','.join(['lol'] * 9)}]"]
        + [f"a{i}: &a{i} [{','.join([f'*a{i - 1}'] * 9)}]" for i in range(1, 9)]
    )
    + "\n"
)


def test_the_alias_bomb_is_small() -> None:
    assert len(ALIAS_BOMB) < 420  # the was 358 bytes


def _peak_bytes(document: str, parse: Any) -> tuple[BaseException | None, int]:
    tracemalloc.start()
    try:
        parse(document)
    except ConfigError as exc:
        return exc, tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    return None, 0


def test_an_alias_bomb_is_refused_before_it_expands(tmp_path: Path) -> None:
    error, peak = _peak_bytes(ALIAS_BOMB, lambda d: parse_yaml(d, "bomb.yaml", CONFIG_LIMITS))
    assert error is not None and "once YAML aliases are expanded" in str(error)
    assert peak < 5_000_000
    path = tmp_path / "bomb.yaml"
    path.write_text(ALIAS_BOMB + "controllers: {}\nmotors: {}\nsensors:\n  s: {x: *a8}\n")
    with pytest.raises(ConfigError, match=r"bomb.yaml: more than 200,000 values"):
        load_config(path)


def test_shared_values_within_limits_are_fine() -> None:
    doc = "base: &b {p: 1, i: 0, d: 0}\nm1: *b\nm2: *b\n"
    assert parse_yaml(doc, "ok.yaml", CONFIG_LIMITS)["m2"] == {"p": 1, "i": 0, "d": 0}


@pytest.mark.parametrize(
    "document",
    ["[" * 100_000 + "]" * 100_000, '{"a":' * 50_000 + "1" + "}" * 50_000, "[" * 40 + "]" * 40],
    ids=["deep list", "deep object", "just too deep"],
)
def test_deep_json_is_one_error(document: str) -> None:
    with pytest.raises(ConfigError, match=r"x.json: nested more than 32 levels deep$"):
        parse_json(document, "x.json", CONFIG_LIMITS)


@pytest.mark.parametrize(
    "document",
    [
        "a: " + "[" * 100_000 + "]" * 100_000,
        "a:\n" + "".join(f"{' ' * i}- \n" for i in range(40)),
        "a: " + "{b: " * 5000 + "1" + "}" * 5000,
    ],
    ids=["deep flow", "deep block", "deep mapping"],
)
def test_deep_yaml_is_one_error(document: str) -> None:
    with pytest.raises(ConfigError, match=r"x.yaml: (nested more than 32 levels deep|YAML syntax)"):
        parse_yaml(document, "x.yaml", CONFIG_LIMITS)


def test_cyclic_yaml_is_refused() -> None:
    with pytest.raises(ConfigError, match="cycle"):
        parse_yaml("&a [*a]", "x.yaml", CONFIG_LIMITS)
    with pytest.raises(ConfigError, match="cycle"):
        parse_yaml("&a {k: *a}", "x.yaml", CONFIG_LIMITS)


def test_huge_numbers_are_one_error() -> None:
    with pytest.raises(ConfigError, match=r"x.json: not valid JSON: .* too many digits"):
        parse_json('{"id": ' + "1" * 6000 + "}", "x.json", CONFIG_LIMITS)
    with pytest.raises(ConfigError, match=r"x.yaml: not valid YAML: Exceeds the limit"):
        parse_yaml("id: " + "1" * 6000, "x.yaml", CONFIG_LIMITS)


def test_long_text_counts_towards_the_limit() -> None:
    text = "x" * 64_000
    doc = f"a: &a '{text}'\nb: [" + ", ".join(["*a"] * 2000) + "]\n"
    with pytest.raises(ConfigError, match="values once YAML aliases"):
        parse_yaml(doc, "x.yaml", Limits(max_bytes=1 << 20, max_nodes=100_000, max_depth=8))


def test_check_shape_counts_expanded_values() -> None:
    shared = list(range(100))
    check_shape([shared] * 10, "ok", Limits(1, max_nodes=1_100, max_depth=3))
    with pytest.raises(ConfigError):
        check_shape([shared] * 11, "big", Limits(1, max_nodes=1_100, max_depth=3))


def test_special_files_are_not_read(tmp_path: Path) -> None:
    fifo = tmp_path / "robot.yaml"
    os.mkfifo(fifo)
    with pytest.raises(ConfigError, match="not a regular file"):
        load_config(fifo)  # no writer: a plain open() would block forever
    with pytest.raises(ConfigError, match="not a regular file"):
        load_config("/dev/zero")
    with pytest.raises(ConfigError, match="it is a folder"):
        load_config(tmp_path)


def test_a_large_file_is_refused_before_it_is_read(tmp_path: Path) -> None:
    path = tmp_path / "big.json"
    with path.open("wb") as handle:
        handle.truncate(CONFIG_LIMITS.max_bytes + 1)
    with pytest.raises(ConfigError, match="at most 1,048,576 are read"):
        load_config(path)


def test_not_utf8(tmp_path: Path) -> None:
    path = tmp_path / "robot.yaml"
    path.write_bytes(b"motors: \xff\xfe")
    with pytest.raises(ConfigError, match="not UTF-8"):
        load_config(path)


def test_a_document_parsed_again_is_a_fresh_copy_of_its_text() -> None:
    # parse_yaml keeps what it parsed per text (a robot's build reads its profile more than
    # once): the caller gets its own copy, and another text is parsed anew
    first = parse_yaml("motors: {m1: {id: 1}}\n", "cached.yaml", CONFIG_LIMITS)
    first["motors"]["m1"]["id"] = 99
    assert parse_yaml("motors: {m1: {id: 1}}\n", "cached.yaml", CONFIG_LIMITS) == {
        "motors": {"m1": {"id": 1}}
    }
    assert parse_yaml("motors: {m1: {id: 2}}\n", "cached.yaml", CONFIG_LIMITS) == {
        "motors": {"m1": {"id": 2}}
    }
