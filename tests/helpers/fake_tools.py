"""Recording fakes of the OS's tools (``hostnamectl``, ``nmcli``, ``systemctl``) put first on
``PATH``: each appends its argv (one JSON list a line) to a log and prints canned output. A
``passwd-file``'s text and mode are logged apart (``secrets()``), its path logged as ``FILE``;
so is what ``nmcli connection edit`` reads on its standard input (``{"stdin": TEXT}``)."""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import pytest

SCRIPT = """#!{python}
import json, os, sys
tool = os.path.basename(sys.argv[0])
argv = [tool, *sys.argv[1:]]
if "passwd-file" in argv[:-1]:  # read the secrets as nmcli would, then log the argument as FILE
    at = argv.index("passwd-file") + 1
    with open(argv[at], encoding="utf-8") as given:
        secrets = {{"text": given.read(), "mode": oct(os.stat(argv[at]).st_mode & 0o777)}}
    with open(os.environ["FAKE_TOOLS_LOG"] + ".secrets", "a", encoding="utf-8") as log:
        log.write(json.dumps(secrets) + "\\n")
    argv[at] = "FILE"
if argv[1:3] == ["connection", "edit"]:  # the editor's commands come on standard input
    with open(os.environ["FAKE_TOOLS_LOG"] + ".secrets", "a", encoding="utf-8") as log:
        log.write(json.dumps({{"stdin": sys.stdin.read()}}) + "\\n")
with open(os.environ["FAKE_TOOLS_LOG"], "a", encoding="utf-8") as log:
    log.write(json.dumps(argv) + "\\n")
canned = json.loads(open(os.environ["FAKE_TOOLS_CANNED"], encoding="utf-8").read())
key = " ".join(argv)
answer = canned.get(key, {{}})
sys.stdout.write(answer.get("out", ""))
sys.stderr.write(answer.get("err", ""))
sys.exit(answer.get("code", 0))
"""

NETWORKS = (
    "*:Class\\:room:72:WPA2\n"  # an SSID with a colon, escaped by nmcli -t
    ":Home Wifi:40:WPA1 WPA2\n"
    ":Home Wifi:55:WPA1 WPA2\n"  # a second access point of the same network
    ":Cafe::\n"
    "::30:WPA2\n"  # a hidden network: no name
)
CONNECTIONS = (
    "Class\\:room:802-11-wireless:0\n"
    "Wired connection 1:802-3-ethernet:-999\n"
    "poppy-hotspot:802-11-wireless:-100\n"
)
CANNED = {
    "nmcli -t -f RUNNING general": {"out": "running\n"},
    "nmcli -t -f IN-USE,SSID,SIGNAL,SECURITY device wifi list": {"out": NETWORKS},
    "nmcli -t -f NAME,TYPE,AUTOCONNECT-PRIORITY connection show": {"out": CONNECTIONS},
    "nmcli -t -f DEVICE,TYPE device": {"out": "eth0:ethernet\nwlan0:wifi\nlo:loopback\n"},
    "systemctl is-active poppy-jupyter.service": {"out": "inactive\n", "code": 3},
    "systemctl --user is-active poppy-jupyter.service": {"out": "active\n"},
    "nmcli connection up id Nowhere passwd-file FILE": {
        "err": "Error: Connection activation failed: Secrets were required, but not provided.\n",
        "code": 4,
    },
}


class FakeTools:
    """The fakes of one test: ``calls()`` are the commands run, ``canned`` their answers."""

    def __init__(self, folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
        self.bin = folder / "bin"
        self.bin.mkdir()
        self.log = folder / "calls.jsonl"
        self.log.touch()
        self.canned_file = folder / "canned.json"
        self.canned = dict(CANNED)
        self.save()
        script = SCRIPT.format(python=sys.executable)
        for tool in ("hostnamectl", "nmcli", "systemctl"):
            path = self.bin / tool
            path.write_text(script, encoding="utf-8")
            path.chmod(0o755)
        monkeypatch.setenv("PATH", f"{self.bin}{os.pathsep}{os.environ.get('PATH', '')}")
        monkeypatch.setenv("FAKE_TOOLS_LOG", str(self.log))
        monkeypatch.setenv("FAKE_TOOLS_CANNED", str(self.canned_file))

    def save(self) -> None:
        """Write ``canned`` for the fakes to read."""
        self.canned_file.write_text(json.dumps(self.canned), encoding="utf-8")

    def calls(self) -> list[list[str]]:
        """Every command run so far, in order."""
        lines = self.log.read_text(encoding="utf-8").splitlines()
        return [json.loads(line) for line in lines if line]

    def secrets(self) -> list[dict[str, str]]:
        """Each ``passwd-file`` given, in order: its text (``text``) and octal mode (``mode``);
        or what ``nmcli connection edit`` read on its standard input (``stdin``)."""
        log = self.log.with_name(self.log.name + ".secrets")
        lines = log.read_text(encoding="utf-8").splitlines() if log.exists() else []
        return [json.loads(line) for line in lines if line]

    def changes(self) -> list[list[str]]:
        """The commands run that change something (reads left out)."""
        reads = ("-t", "is-active")
        return [c for c in self.calls() if not any(r in c for r in reads)]

    def remove(self, tool: str) -> None:
        """Take ``tool`` away (a machine without it)."""
        (self.bin / tool).unlink()

    def alone(self, monkeypatch: pytest.MonkeyPatch) -> None:
        """Make the fakes the only programs on ``PATH`` (the machine's own tools hidden)."""
        monkeypatch.setenv("PATH", str(self.bin))
