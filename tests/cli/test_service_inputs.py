"""`poppy service install` and the page's service switches against hostile or careless input
(issue 35.4): a control character in a unit field is refused in one line (exit 2), the files are
written with their own modes whatever the umask, and the polkit rule grants what the page's
switches run (checked by running the rule's JavaScript under Node.js, as polkit would)."""

from __future__ import annotations

import json
import os
import shutil
import stat
import subprocess
from pathlib import Path

import pytest

from poppy_cli.service_polkit import rule_text
from poppy_cli.service_unit import JUPYTER_UNIT, UNIT
from poppy_core.server.settings_os import SystemTools
from tests.cli.test_service_cmd import Fake, fake, someone  # noqa: F401 (fixtures)
from tests.helpers.fake_tools import FakeTools

UNIT_ACTIONS = {"start", "stop", "restart", "try-restart", "reload", "reload-or-restart"}
"""systemctl verbs that polkit asks as org.freedesktop.systemd1.manage-units with the unit and
the verb (systemd's policy); ``enable``/``disable`` are manage-unit-files, for any unit."""


@pytest.mark.parametrize(
    ("flag", "value"),
    [
        ("--port", "/dev/ttyAMA0\nExecStartPre=/bin/sh -c 'id > /tmp/owned'"),
        ("--host", "0.0.0.0\nExecStartPre=/bin/true"),
        ("--port", "/dev/tty\x00AMA0"),
        ("--host", "0.0.0.0\r"),
        ("--port", "/dev/ttyAMA0\x1b[2J"),
    ],
)
def test_a_control_character_in_a_unit_field_is_refused_in_one_line(
    fake: Fake,  # noqa: F811
    someone: str,  # noqa: F811
    flag: str,
    value: str,
) -> None:
    if "\x00" in value:  # a NUL cannot be a command-line argument: the unit's rule is checked
        from poppy_cli.service_unit import ServiceSpec, units
        from poppy_core.errors import ArgumentError

        with pytest.raises(ArgumentError, match="control character"):
            units(ServiceSpec(poppy=("poppy",), port=value))
        return
    result = fake.run("install", "--run-as", someone, flag, value)
    assert result.code == 2, result.stderr
    assert f"{flag} " in result.stderr and "control character" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1, result.stderr
    assert "Traceback" not in result.stderr
    assert fake.calls() == [] and not fake.units.exists()
    dry = fake.run("install", "--run-as", someone, flag, value, "--dry-run")
    assert dry.code == 2 and "ExecStartPre" not in dry.stdout


def test_under_umask_000_every_file_and_folder_gets_its_own_mode(
    fake: Fake,  # noqa: F811
    someone: str,  # noqa: F811
) -> None:
    old = os.umask(0)
    try:
        result = fake.run("install", "--run-as", someone, "--jupyter", "--require-token")
    finally:
        os.umask(old)
    assert result.code == 0, result.stderr

    def mode(path: Path) -> int:
        return stat.S_IMODE(path.stat().st_mode)

    assert mode(fake.units / UNIT) == 0o644 and mode(fake.units / JUPYTER_UNIT) == 0o644
    assert mode(fake.polkit / "50-poppy.rules") == 0o644
    assert mode(fake.files / "serve.json") == 0o644 and mode(fake.files / "token") == 0o600
    for folder in (fake.units, fake.polkit, fake.files):
        assert mode(folder) & 0o022 == 0, f"{folder} is {oct(mode(folder))}"


def _asked(argv: list[str]) -> tuple[str, str, str]:
    """The polkit question a systemctl command asks: (action, unit, verb)."""
    words = [a for a in argv[1:] if not a.startswith("-")]
    verb, unit = words[0], words[-1]
    if verb in UNIT_ACTIONS:
        return "org.freedesktop.systemd1.manage-units", unit, verb
    return "org.freedesktop.systemd1.manage-unit-files", unit, verb


def test_the_polkit_rule_grants_every_command_of_the_page_s_switches(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    node = shutil.which("node")
    if node is None:
        pytest.skip("Node.js is not installed: the rule's JavaScript is not run")
    tools_fake = FakeTools(tmp_path, monkeypatch)
    tools = SystemTools(user_units=False)
    tools.set_service(JUPYTER_UNIT, True)  # the page's Jupyter switch, on then off
    tools.set_service(JUPYTER_UNIT, False)
    tools.restart_later(UNIT)  # Snap!/ZMQ/token changes restart the service
    questions = [_asked(c) for c in tools_fake.calls() if c[0] == "systemctl"]
    assert len(questions) == 3
    probe = tmp_path / "rule.js"
    probe.write_text(
        "var rules = [];\n"
        'var polkit = {Result: {YES: "yes", NOT_HANDLED: "no"}, '
        "addRule: function (f) { rules.push(f); }};\n"
        + rule_text("pi", (UNIT, JUPYTER_UNIT))
        + "function ask(q) {\n"
        '  var action = {id: q[0], lookup: function (k) { return k == "unit" ? q[1] : q[2]; }};\n'
        '  return rules[0](action, {user: "pi"});\n'
        "}\n"
        f"console.log({json.dumps(questions)}.map(ask).join(' '));\n"
    )
    out = subprocess.run([node, str(probe)], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["yes"] * len(questions), questions
