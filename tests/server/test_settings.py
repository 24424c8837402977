"""The settings: the adapter's exact commands against recording fakes of hostnamectl, nmcli and
systemctl on PATH, and the routes: a change without the token (or on a server without one) is
refused and runs nothing; elsewhere than on a NetworkManager machine they are read-only."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest

from poppy_core.server.settings_os import (
    HOTSPOT,
    Network,
    SavedNetwork,
    SystemToolError,
    SystemTools,
    printable_command,
    split_terse,
    user_manager,
)
from tests.helpers.fake_tools import FakeTools
from tests.helpers.server import Served, serve
from tests.helpers.waiting import http_timeout

TOKEN = "s3cret"
BEARER = {"Authorization": f"Bearer {TOKEN}"}


def join_add(ssid: str) -> list[str]:
    """The connection a WPA network is joined with, made without its key."""
    return [
        *("nmcli", "connection", "add", "type", "wifi", "ifname", "wlan0", "con-name", ssid),
        *("ssid", ssid, "wifi-sec.key-mgmt", "wpa-psk"),
    ]


def join_up(ssid: str) -> list[str]:
    """Starting it with the key in a file (the fake logs the file's path as FILE)."""
    return ["nmcli", "connection", "up", "id", ssid, "passwd-file", "FILE"]


SAVED = ["nmcli", "-t", "-f", "NAME,TYPE,AUTOCONNECT-PRIORITY", "connection", "show"]
DEVICE = ["nmcli", "-t", "-f", "DEVICE,TYPE", "device"]
HOTSPOT_ADD = [
    "nmcli",
    "connection",
    "add",
    "type",
    "wifi",
    "ifname",
    "wlan0",
    "con-name",
    "poppy-hotspot",
    "autoconnect",
    "yes",
    "ssid",
    "ergo-2",
    "connection.autoconnect-priority",
    "-100",
    "802-11-wireless.mode",
    "ap",
    "ipv4.method",
    "shared",
    "wifi-sec.key-mgmt",
    "wpa-psk",
]
"""The fallback access point as NetworkManager is asked to make it (without its key)."""
HOTSPOT_EDIT = ["nmcli", "connection", "edit", "id", HOTSPOT]
"""Its key set through nmcli's editor, the commands on standard input."""


def hotspot_key(password: str) -> dict[str, str]:
    """What the editor reads on its standard input to set the access point's key."""
    return {"stdin": f"set 802-11-wireless-security.psk {password}\nsave persistent\nquit\n"}


@pytest.fixture
def fake(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> FakeTools:
    return FakeTools(tmp_path, monkeypatch)


@pytest.fixture(scope="module")
def with_token(moves_folder: str) -> Iterator[Served]:
    yield from serve(moves_folder, token=TOKEN)


@pytest.fixture(scope="module")
def without_token(moves_folder: str) -> Iterator[Served]:
    yield from serve(moves_folder)


# -- the adapter -------------------------------------------------------------------------------


def test_the_adapter_runs_exactly_these_commands(fake: FakeTools) -> None:
    tools = SystemTools(user_units=False)
    assert tools.unavailable() is None
    tools.set_hostname("ergo-2")
    tools.join("Home Wifi", "password1")
    tools.join("Cafe", None)
    tools.forget("Home Wifi")
    tools.set_hotspot("ergo-2", "hotspot-pw")
    tools.remove_hotspot()
    tools.set_service("poppy-jupyter.service", True)
    tools.set_service("poppy-jupyter.service", False)
    assert tools.service_active("poppy-jupyter.service") is False
    assert fake.calls() == [
        ["nmcli", "-t", "-f", "RUNNING", "general"],
        ["hostnamectl", "set-hostname", "ergo-2"],
        SAVED,
        DEVICE,
        join_add("Home Wifi"),
        join_up("Home Wifi"),
        ["nmcli", "device", "wifi", "connect", "Cafe"],
        ["nmcli", "connection", "delete", "id", "Home Wifi"],
        ["nmcli", "-t", "-f", "NAME,TYPE,AUTOCONNECT-PRIORITY", "connection", "show"],
        ["nmcli", "connection", "delete", "id", HOTSPOT],  # remade, not doubled
        ["nmcli", "-t", "-f", "DEVICE,TYPE", "device"],
        HOTSPOT_ADD,
        HOTSPOT_EDIT,
        ["nmcli", "-t", "-f", "NAME,TYPE,AUTOCONNECT-PRIORITY", "connection", "show"],
        ["nmcli", "connection", "delete", "id", HOTSPOT],
        ["systemctl", "start", "poppy-jupyter.service"],
        ["systemctl", "stop", "poppy-jupyter.service"],
        ["systemctl", "is-active", "poppy-jupyter.service"],
    ]


def test_a_user_service_is_reached_with_systemctl_user(fake: FakeTools) -> None:
    tools = SystemTools(user_units=True)
    tools.set_service("poppy-jupyter.service", True)
    assert tools.service_active("poppy-jupyter.service") is True
    assert fake.calls() == [
        ["systemctl", "--user", "start", "poppy-jupyter.service"],
        ["systemctl", "--user", "is-active", "poppy-jupyter.service"],
    ]


def test_networks_and_saved_ones_are_read_from_nmcli_terse_output(fake: FakeTools) -> None:
    tools = SystemTools(user_units=False)
    assert tools.networks() == [
        Network("Class:room", 72, "WPA2", True),
        Network("Home Wifi", 55, "WPA1 WPA2", False),
        Network("Cafe", 0, "open", False),
    ]
    assert tools.saved() == [SavedNetwork("Class:room", 0), SavedNetwork(HOTSPOT, -100)]


def test_the_wifi_key_reaches_nmcli_in_a_private_file_never_on_a_command_line(
    fake: FakeTools,
) -> None:
    tools = SystemTools(user_units=False)
    tools.join("Class:room", "password1")  # saved already: remade with the new key
    assert fake.calls() == [
        SAVED,
        ["nmcli", "connection", "delete", "id", "Class:room"],
        DEVICE,
        join_add("Class:room"),
        join_up("Class:room"),
    ]
    assert fake.secrets() == [{"text": "802-11-wireless-security.psk:password1\n", "mode": "0o600"}]
    assert not any("password1" in arg for call in fake.calls() for arg in call)


def test_the_access_point_key_reaches_nmcli_on_standard_input_never_on_a_command_line(
    fake: FakeTools,
) -> None:
    SystemTools(user_units=False).set_hotspot("ergo-2", "ap secret~1")
    assert fake.changes() == [
        ["nmcli", "connection", "delete", "id", HOTSPOT],
        HOTSPOT_ADD,
        HOTSPOT_EDIT,
    ]
    assert fake.secrets() == [hotspot_key("ap secret~1")]
    assert not any("secret" in arg for call in fake.calls() for arg in call)


def test_an_access_point_whose_key_cannot_be_set_is_removed(fake: FakeTools) -> None:
    fake.canned[" ".join(HOTSPOT_EDIT)] = {"err": "Error: invalid psk.\n", "code": 1}
    fake.save()
    with pytest.raises(SystemToolError) as caught:
        SystemTools(user_units=False).set_hotspot("ergo-2", "ap-secret-2")
    assert "invalid psk" in str(caught.value) and "ap-secret-2" not in str(caught.value)
    assert fake.changes()[-2:] == [HOTSPOT_EDIT, ["nmcli", "connection", "delete", "id", HOTSPOT]]
    assert not any("ap-secret-2" in arg for call in fake.calls() for arg in call)


def test_a_refused_key_is_one_line_without_it_and_leaves_no_connection(fake: FakeTools) -> None:
    with pytest.raises(SystemToolError) as caught:
        SystemTools(user_units=False).join("Nowhere", "wrongpass1")
    message = str(caught.value)
    assert "\n" not in message and "Secrets were required" in message
    assert "wrongpass1" not in message
    assert fake.changes() == [
        join_add("Nowhere"),
        join_up("Nowhere"),
        ["nmcli", "connection", "delete", "id", "Nowhere"],
    ]
    assert fake.secrets() == [
        {"text": "802-11-wireless-security.psk:wrongpass1\n", "mode": "0o600"}
    ]
    assert not any("wrongpass1" in arg for call in fake.calls() for arg in call)


def test_without_networkmanager_the_reason_is_given(
    fake: FakeTools, monkeypatch: pytest.MonkeyPatch
) -> None:
    fake.alone(monkeypatch)
    fake.remove("nmcli")
    reason = SystemTools(user_units=False).unavailable()
    assert reason is not None and "nmcli not found" in reason


def test_networkmanager_stopped_is_a_reason(fake: FakeTools) -> None:
    fake.canned["nmcli -t -f RUNNING general"] = {"out": "stopped\n"}
    fake.save()
    reason = SystemTools(user_units=False).unavailable()
    assert reason is not None and "NetworkManager is not running" in reason


def test_small_rules() -> None:
    assert split_terse("a\\:b:c\\\\d:") == ["a:b", "c\\d", ""]
    assert user_manager("0::/user.slice/user-1000.slice/user@1000.service/app.slice/x.service")
    assert not user_manager("0::/system.slice/poppy.service")
    assert printable_command(["nmcli", "x", "password", "pw"]) == "nmcli x password ***"


# -- the routes --------------------------------------------------------------------------------


def test_a_change_without_the_token_is_refused_and_runs_nothing(
    fake: FakeTools, with_token: Served
) -> None:
    with httpx.Client(base_url=with_token.url, timeout=http_timeout(30)) as http:
        for method, path, body in [
            ("PUT", "/api/v1/settings/name", {"name": "ergo-2"}),
            ("POST", "/api/v1/settings/wifi/join", {"ssid": "Home Wifi", "password": "pw123456"}),
            ("PUT", "/api/v1/settings/services/jupyter", {"on": True}),
            ("GET", "/api/v1/settings", None),
        ]:
            answer = http.request(method, path, json=body)
            assert answer.status_code == 401, (path, answer.text)
            wrong = http.request(method, path, json=body, headers={"Authorization": "Bearer x"})
            assert wrong.status_code == 401
    assert fake.calls() == []


def test_a_server_without_a_token_shows_settings_read_only(
    fake: FakeTools, without_token: Served
) -> None:
    with httpx.Client(base_url=without_token.url, timeout=http_timeout(30)) as http:
        shown = http.get("/api/v1/settings").json()
        assert shown["editable"] is False and "--token" in shown["reason"]
        answer = http.put("/api/v1/settings/name", json={"name": "ergo-2"})
        assert answer.status_code == 403 and "--token" in answer.json()["detail"]
    assert fake.changes() == []


def test_with_the_token_the_robot_is_renamed_and_answers_its_new_name(
    fake: FakeTools, with_token: Served
) -> None:
    port = with_token.url.rsplit(":", 1)[1]
    with httpx.Client(base_url=with_token.url, headers=BEARER, timeout=http_timeout(30)) as http:
        shown = http.get("/api/v1/settings").json()
        assert shown["editable"] is True and shown["reason"] is None
        assert shown["token_required"] is True and shown["version"]
        assert shown["services"]["jupyter"] == {
            "on": False,
            "unit": "poppy-jupyter.service",
            "how": "systemctl",
        }
        assert http.get("/", headers={"Host": f"ergo-2.local:{port}"}).status_code == 400
        answer = http.put("/api/v1/settings/name", json={"name": "Ergo-2"})
        assert answer.status_code == 200, answer.text
        assert answer.json() == {"name": "ergo-2", "host": "ergo-2.local"}
        assert http.get("/", headers={"Host": f"ergo-2.local:{port}"}).status_code == 200
        assert http.get("/api/v1/settings").json()["name"] == "ergo-2"
    assert fake.changes() == [["hostnamectl", "set-hostname", "ergo-2"]]


def test_wifi_and_services_from_the_routes(fake: FakeTools, with_token: Served) -> None:
    with_token.app.state.settings.served.name = "ergo-2"  # the access point is named after it
    with httpx.Client(base_url=with_token.url, headers=BEARER, timeout=http_timeout(30)) as http:
        wifi = http.get("/api/v1/settings/wifi").json()
        assert [n["ssid"] for n in wifi["networks"]] == ["Class:room", "Home Wifi", "Cafe"]
        assert http.post(
            "/api/v1/settings/wifi/join", json={"ssid": "Home Wifi", "password": "password1"}
        ).json() == {"joined": "Home Wifi"}
        assert http.post("/api/v1/settings/wifi/forget", json={"name": "Class:room"}).is_success
        assert http.put(
            "/api/v1/settings/wifi/hotspot", json={"on": True, "password": "hotspot-pw"}
        ).json() == {"on": True, "ssid": "ergo-2"}
        assert http.put("/api/v1/settings/services/jupyter", json={"on": True}).is_success
        failed = http.post(
            "/api/v1/settings/wifi/join", json={"ssid": "Nowhere", "password": "wrongpass1"}
        )
        assert failed.status_code == 409 and "Secrets were required" in failed.json()["detail"]
    assert fake.changes() == [
        join_add("Home Wifi"),
        join_up("Home Wifi"),
        ["nmcli", "connection", "delete", "id", "Class:room"],
        ["nmcli", "connection", "delete", "id", HOTSPOT],
        HOTSPOT_ADD,
        HOTSPOT_EDIT,
        ["systemctl", "start", "poppy-jupyter.service"],
        join_add("Nowhere"),
        join_up("Nowhere"),
        ["nmcli", "connection", "delete", "id", "Nowhere"],
    ]


@pytest.mark.parametrize(
    ("method", "path", "body", "status"),
    [
        ("PUT", "/api/v1/settings/name", {"name": "bad name"}, 422),
        ("PUT", "/api/v1/settings/name", {"name": "-x"}, 422),
        ("POST", "/api/v1/settings/wifi/join", {"ssid": "", "password": None}, 422),
        ("POST", "/api/v1/settings/wifi/join", {"ssid": "Home", "password": "short"}, 422),
        ("PUT", "/api/v1/settings/wifi/hotspot", {"on": True}, 422),
        # a NUL, a control or a non-ASCII character is no WPA password (8-63 printable ASCII)
        ("POST", "/api/v1/settings/wifi/join", {"ssid": "Home", "password": "pass\x00word1"}, 422),
        ("POST", "/api/v1/settings/wifi/join", {"ssid": "Home", "password": "pass\tword1"}, 422),
        ("POST", "/api/v1/settings/wifi/join", {"ssid": "Home", "password": "pässwörd12"}, 422),
        ("POST", "/api/v1/settings/wifi/join", {"ssid": "Home", "password": "f" * 63 + "g"}, 422),
        ("PUT", "/api/v1/settings/wifi/hotspot", {"on": True, "password": "hotspot\x7fpw"}, 422),
        # an SSID is 1-32 bytes, and one starting with '-' would reach nmcli as an option
        ("POST", "/api/v1/settings/wifi/join", {"ssid": "--ask", "password": None}, 422),
        ("POST", "/api/v1/settings/wifi/join", {"ssid": "é" * 17, "password": None}, 422),
        ("POST", "/api/v1/settings/wifi/join", {"ssid": "Home\nWifi", "password": None}, 422),
        # only a saved Wi-Fi network is forgotten: never the Ethernet connection
        ("POST", "/api/v1/settings/wifi/forget", {"name": "Wired connection 1"}, 422),
        ("POST", "/api/v1/settings/wifi/forget", {"name": "Nowhere"}, 422),
        ("PUT", "/api/v1/settings/services/snap", {"on": True}, 409),
        ("PUT", "/api/v1/settings/services/nothing", {"on": True}, 404),
    ],
)
def test_bad_changes_are_refused_in_one_line_and_run_nothing(
    fake: FakeTools, with_token: Served, method: str, path: str, body: object, status: int
) -> None:
    with httpx.Client(base_url=with_token.url, headers=BEARER, timeout=http_timeout(30)) as http:
        answer = http.request(method, path, json=body)
    assert answer.status_code == status, answer.text
    detail = answer.json()["detail"]
    assert isinstance(detail, str) and "\n" not in detail
    assert fake.changes() == []


def test_a_64_hex_digit_key_and_printable_ascii_are_wpa_passwords(
    fake: FakeTools, with_token: Served
) -> None:
    key = "0123456789abcdef" * 4
    with httpx.Client(base_url=with_token.url, headers=BEARER, timeout=http_timeout(30)) as http:
        for password in (key, "a b~c!d{e}"):
            answer = http.post(
                "/api/v1/settings/wifi/join", json={"ssid": "Home Wifi", "password": password}
            )
            assert answer.status_code == 200, answer.text
    assert fake.changes() == [join_add("Home Wifi"), join_up("Home Wifi")] * 2
    assert [secret["text"] for secret in fake.secrets()] == [
        f"802-11-wireless-security.psk:{key}\n",
        "802-11-wireless-security.psk:a b~c!d{e}\n",
    ]


def test_elsewhere_the_settings_are_read_only_with_the_reason(
    fake: FakeTools, with_token: Served, monkeypatch: pytest.MonkeyPatch
) -> None:
    fake.alone(monkeypatch)
    fake.remove("nmcli")
    with httpx.Client(base_url=with_token.url, headers=BEARER, timeout=http_timeout(30)) as http:
        shown = http.get("/api/v1/settings").json()
        assert shown["editable"] is False and "nmcli not found" in shown["reason"]
        assert shown["services"]["jupyter"]["on"] is None
        answer = http.put("/api/v1/settings/name", json={"name": "ergo-3"})
        assert answer.status_code == 409 and "nmcli not found" in answer.json()["detail"]
    assert fake.changes() == []


def test_an_unnamed_robot_s_access_point_is_named_after_the_machine_or_poppy(
    fake: FakeTools, with_token: Served, monkeypatch: pytest.MonkeyPatch
) -> None:
    import poppy_core.server.settings_os as settings_os
    from poppy_core import zenoh_wire

    with_token.app.state.settings.served.name = None
    body = {"on": True, "password": "hotspot-pw"}
    with httpx.Client(base_url=with_token.url, headers=BEARER, timeout=http_timeout(30)) as http:
        monkeypatch.setattr(settings_os.socket, "gethostname", lambda: "Ergo-9.lan")
        assert http.put("/api/v1/settings/wifi/hotspot", json=body).json()["ssid"] == "ergo-9"
        # the machine's robot name, as Zenoh's default name makes it (one rule)
        monkeypatch.setattr(settings_os.socket, "gethostname", lambda: "my_machine")
        assert http.put("/api/v1/settings/wifi/hotspot", json=body).json()["ssid"] == "my-machine"
        monkeypatch.setattr(zenoh_wire.socket, "gethostname", lambda: "my_machine")
        assert zenoh_wire.default_name() == "my-machine"
        monkeypatch.setattr(settings_os.socket, "gethostname", lambda: "__")
        assert http.put("/api/v1/settings/wifi/hotspot", json=body).json()["ssid"] == "poppy"
