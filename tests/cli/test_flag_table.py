"""One meaning per flag: every option of every command against the table of poppy_cli/flags.py.

The checks walk the command tree as built, so an option added later is checked too: a new long
flag must be given its short flag, value and meaning in ``FLAGS`` (and docs/cli.md's table).
"""

from __future__ import annotations

import re
from collections import defaultdict
from pathlib import Path
from typing import Any, get_args, get_origin

import pytest

from poppy_cli.flags import DEPRECATED, FLAGS, flag_table_markdown
from tests.helpers.cli_tree import options, parse, walk

DOCS = Path(__file__).resolve().parents[2] / "docs" / "cli.md"

KIND_EXCEPTIONS = {
    "--protocol": "scan takes `both` besides 1 and 2",
    # the flag COORD agreed for the Jupyter service unit (`poppy notebook --port 8888`)
    "--port": "notebook takes the Jupyter server's TCP port, the others a serial port",
}
"""Long flags whose value is of one kind in some commands and another elsewhere, and why."""


def _longs(option: Any) -> list[str]:
    return [o for o in (*option.opts, *option.secondary_opts) if o.startswith("--")]


def _shorts(option: Any) -> list[str]:
    return [o for o in (*option.opts, *option.secondary_opts) if not o.startswith("--")]


def _uses() -> list[tuple[str, Any]]:
    return [(path, option) for path, command in walk() for option in options(command)]


def _where(path: str) -> str:
    return f"`poppy {path}`".replace(" `", "`")


def test_every_long_flag_is_in_the_table() -> None:
    missing = {
        name: _where(path)
        for path, option in _uses()
        for name in _longs(option)
        if name not in FLAGS
    }
    assert not missing, (
        f"add these flags to FLAGS in poppy_cli/flags.py (short flag, value, meaning) and to "
        f"docs/cli.md: {missing}"
    )


def test_a_short_flag_means_one_long_flag_everywhere() -> None:
    meanings: dict[str, set[str]] = defaultdict(set)
    for _, option in _uses():
        for short in _shorts(option):
            meanings[short].update(_longs(option))
    several = {short: sorted(longs) for short, longs in meanings.items() if len(longs) > 1}
    assert not several, f"short flags standing for several long flags: {several}"


def test_each_long_flag_has_its_short_flag_everywhere() -> None:
    wrong = []
    for path, option in _uses():
        names = [name for name in _longs(option) if name in FLAGS]
        expected = [FLAGS[name].short for name in names if FLAGS[name].short]
        if names and _shorts(option) != expected:
            wrong.append(f"{_where(path)} {names[0]}: {_shorts(option)}, table: {expected}")
    assert not wrong, wrong


def test_no_two_options_of_a_command_share_a_flag() -> None:
    clashes = []
    for path, command in walk():
        seen: dict[str, str] = {}
        for option in options(command):
            for flag in (*option.opts, *option.secondary_opts):
                if flag in seen:
                    clashes.append(f"{_where(path)}: {flag} is {seen[flag]} and {option.name}")
                seen[flag] = option.name
    assert not clashes, clashes


def _kind(option: Any) -> str:
    """on/off, number or text: what a flag's value is made of (a repeated option as its item)."""
    if option.is_flag:
        return "flag"
    annotation = option.type_descriptor.annotation
    if get_origin(annotation) is list:
        annotation = get_args(annotation)[0]
    return "number" if annotation in (int, float) else "text"


def test_a_long_flag_takes_one_kind_of_value() -> None:
    kinds: dict[str, set[str]] = defaultdict(set)
    for _, option in _uses():
        for name in _longs(option):
            kinds[name].add(_kind(option))
    mixed = {n: sorted(k) for n, k in kinds.items() if len(k) > 1 and n not in KIND_EXCEPTIONS}
    assert not mixed, f"long flags with values of several kinds (two meanings?): {mixed}"
    for name, kind in kinds.items():
        flag = FLAGS.get(name)
        if flag is not None:
            assert (flag.value is None) == (kind == {"flag"}), (name, flag, kind)


def test_docs_carry_the_flag_table() -> None:
    docs = DOCS.read_text(encoding="utf-8")
    assert flag_table_markdown() in docs, "docs/cli.md: paste poppy_cli.flags.flag_table_markdown()"


@pytest.mark.parametrize("alias", DEPRECATED, ids=lambda a: f"{' '.join(a.command)} {a.old}")
def test_deprecated_spellings_still_work_with_a_warning(
    alias: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    commands = dict(walk())
    command = commands[" ".join(alias.command)]
    visible = {flag for option in options(command) for flag in option.opts}
    assert alias.old not in visible and alias.new in visible
    option = next(o for o in options(command) if alias.new in o.opts)
    # a number within the option's range (a baud rate is 1200 bps at least, a loop count 2)
    value = ("57600" if "baud" in alias.new else "2") if _kind(option) == "number" else "dummy"
    needed = {
        ("robot", "goto"): ["m1=1"],
        ("play",): ["wave"],
        ("motor", "reset"): ["1", "2"],
        ("config", "generate"): ["-o", "robot.yaml"],
        ("camera", "snapshot"): ["-o", "x.png"],
    }.get(alias.command, [])
    old = parse([*alias.command, *needed, alias.old, value])
    warning = rf"warning: `{alias.old}` is deprecated: use `{alias.new}`"
    assert re.search(warning, capsys.readouterr().err)
    new = parse([*alias.command, *needed, alias.new, value])
    assert capsys.readouterr().err == ""
    assert old == new and str(new.params[option.name]) == value


def test_record_freq_and_force_are_two_flags() -> None:
    """`-f` was both `--freq` and `--force` in `record` (`-f 20`: an extra argument)."""
    record = dict(walk())["record"]
    assert [o.name for o in options(record) if "-f" in o.opts] == ["force"]
    parsed = parse(["record", "wave", "--freq", "20", "-f"])
    assert parsed.params["freq"] == 20 and parsed.params["force"] is True


def test_follower_sim_is_spelled_as_sim() -> None:
    bare = parse(["teleop", "--follower", "ergo-jr", "--follower-sim"])
    assert bare.params["follower_sim"] == "ideal"
    parsed = parse(["teleop", "--follower", "ergo-jr", "--follower-sim", "mujoco", "-d", "1"])
    assert parsed.params["follower_sim"] == "mujoco" and parsed.params["duration"] == 1


def test_baud_rates_are_baud_and_the_web_port_is_http_port() -> None:
    """`--rate` was a baud rate in `motor reset` and ticks per second in `teleop`."""
    assert parse(["motor", "reset", "1", "2", "--target-baud", "57600"]).params["rate"] == 57600
    assert parse(["tui", "--http-port", "9000"]).params["web_port"] == 9000
    for path, option in _uses():
        if "--rate" in option.opts:
            assert "second" in (option.help or ""), (path, option.help)
