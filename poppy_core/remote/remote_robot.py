"""``RemoteRobot``, ``RemoteMotor``, ``RemoteGoto``: ``Robot`` over HTTP.

The server's primitives and moves, which a ``RemoteRobot`` hands out, are in ``remote_motion``.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from poppy_core.errors import (
    CommunicationError,
    UnknownGroupError,
    UnknownMotorError,
    UnknownPrimitiveError,
)
from poppy_core.remote.client import DEFAULT_TIMEOUT_S, HttpClient, path_of
from poppy_core.remote.remote_motion import RemoteMoves, RemotePrimitive
from poppy_core.zenoh_wire import ZenohSettings

_OWN = ("_client", "name", "id", "model", "registers")


@dataclass(frozen=True)
class ModelInfo:
    """The servo model of a remote motor (by name, like ``ServoModel.name``)."""

    name: str


class RemoteGoto:
    """A goto started on the server (``GotoHandle``'s interface, timed on this side)."""

    def __init__(self, duration_s: float, done: bool = False) -> None:
        self.duration_s = duration_s
        self._end = time.monotonic() + (0.0 if done else duration_s)

    @property
    def done(self) -> bool:
        """True once the motion should be over."""
        return time.monotonic() >= self._end

    def wait(self, timeout_s: float | None = None) -> bool:
        """Sleep until the motion should be over; False when ``timeout_s`` ran out first."""
        left = self._end - time.monotonic()
        if timeout_s is not None and timeout_s < left:
            time.sleep(max(0.0, timeout_s))
            return False
        time.sleep(max(0.0, left))
        return True


class RemoteMotor:
    """A motor of a remote robot: each register is an attribute read/written over HTTP.

    Attributes:
        name: the motor's name.
        id: its bus ID.
        model: its model (``model.name``).
        registers: the register names it offers (as ``Motor.registers``).
    """

    def __init__(self, client: HttpClient, info: Mapping[str, Any]) -> None:
        object.__setattr__(self, "_client", client)
        object.__setattr__(self, "name", str(info["name"]))
        object.__setattr__(self, "id", int(info["id"]))
        object.__setattr__(self, "model", ModelInfo(str(info["model"])))
        object.__setattr__(self, "registers", list(info["registers"]))

    def __repr__(self) -> str:
        return f"<RemoteMotor {self.name} id={self.id} {self.model.name}>"

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_") or name not in self.__dict__.get("registers", ()):
            raise AttributeError(f"motor {self.__dict__.get('name')!r} has no register {name!r}")
        return self._client.get(path_of("motors", self.name, "registers", name))["value"]

    def __setattr__(self, name: str, value: Any) -> None:
        if name in _OWN:
            raise AttributeError(f"{name} cannot be changed")
        if name not in self.registers:
            raise AttributeError(f"motor {self.name!r} has no register {name!r}")
        path = path_of("motors", self.name, "registers", name)
        self._client.request("PUT", path, {"value": value})

    def __dir__(self) -> list[str]:
        return sorted({*super().__dir__(), *self.registers})

    def _info(self) -> dict[str, Any]:
        info = self._client.get(path_of("motors", self.name))
        assert isinstance(info, dict)
        return info

    @property
    def online(self) -> bool:
        """False once the server's sync loop found the motor silent."""
        return bool(self._info()["online"])

    @property
    def errors(self) -> int:
        """Failed reads so far (on the server)."""
        return int(self._info()["errors"])

    def snapshot(self) -> dict[str, Any]:
        """Every register's value in one request."""
        values = self._info()["registers"]
        assert isinstance(values, dict)
        return values

    def goto_position(
        self, position: float, duration: float, control: str = "minjerk", wait: bool = False
    ) -> RemoteGoto:
        """Go to ``position`` (degrees) in ``duration`` seconds (see ``Motor.goto_position``)."""
        return _goto(self._client, {self.name: position}, duration, control, wait)


def _goto(
    client: HttpClient, positions: Mapping[str, float], duration: float, control: str, wait: bool
) -> RemoteGoto:
    body = {
        "positions": {k: float(v) for k, v in positions.items()},
        "duration_s": float(duration),
        "control": control,
        "wait": wait,
    }
    answer = client.request("POST", path_of("gotos"), body)
    return RemoteGoto(float(duration), done=bool(answer.get("done")))


class RemoteRobot:
    """A robot served by ``poppy serve --http``: ``robot.m1.goal_position = 10`` works as on
    a local ``Robot``.

    Args:
        url: ``http://host:port`` of the server, or ``zenoh:NAME`` for a robot served with
            ``poppy serve --zenoh --name NAME`` (the same API over Zenoh).
        token: the server's token, if it has one.
        timeout_s: socket timeout of each request.
        zenoh: how to join the Zenoh network for ``zenoh:NAME`` (default:
            ``zenoh_client.client_settings()``: POPPY_ZENOH_CONNECT, else tcp/127.0.0.1:7447).

    Raises:
        CommunicationError: the server cannot be reached.
        ConfigError: it refused the token.
    """

    def __init__(
        self,
        url: str,
        token: str | None = None,
        timeout_s: float = DEFAULT_TIMEOUT_S,
        *,
        zenoh: ZenohSettings | None = None,
    ) -> None:
        self.url = url
        self._client = _client(url, token, timeout_s, zenoh)
        try:
            infos = self._client.get(path_of("motors"))
            self._motors = [RemoteMotor(self._client, info) for info in infos]
            robot = self._client.get(path_of("robot"))
            groups = {str(g): [str(m) for m in ms] for g, ms in robot["groups"].items()}
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            self._client.close()
            raise CommunicationError(
                f"{url} is not a poppy server: its robot description is not poppy's "
                f"({type(exc).__name__}: {exc}); is `poppy serve --http` running there?",
                port=url,
            ) from None
        except BaseException:
            self._client.close()
            raise
        self._by_name = {m.name: m for m in self._motors}
        self._groups: dict[str, list[str]] = groups
        self.moves = RemoteMoves(self._client)
        """Record, save, play, stop, delete and list the server's moves."""

    def __repr__(self) -> str:
        return f"<RemoteRobot {self.url} motors={list(self._by_name)}>"

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        if name in self.__dict__.get("_by_name", {}):
            return self._by_name[name]
        if name in self.__dict__.get("_groups", {}):
            return self.group(name)
        if "_client" in self.__dict__ and name in self.primitive_names:
            return RemotePrimitive(self._client, name)  # pypot's ``robot.dance.start()``
        raise AttributeError(f"remote robot has no motor, group or primitive {name!r}")

    def __dir__(self) -> list[str]:
        return sorted({*super().__dir__(), *self._by_name, *self._groups})

    @property
    def motors(self) -> list[RemoteMotor]:
        """Every motor, in config order."""
        return list(self._motors)

    @property
    def motorgroups(self) -> dict[str, list[RemoteMotor]]:
        """Group name -> its motors."""
        return {g: [self._by_name[n] for n in names] for g, names in self._groups.items()}

    def motor(self, name: str) -> RemoteMotor:
        """The motor called ``name``."""
        try:
            return self._by_name[name]
        except KeyError:
            known = list(self._by_name)
            raise UnknownMotorError(
                f"no motor {name!r} (motors: {', '.join(known)})", motor=str(name), known=known
            ) from None

    def group(self, name: str) -> list[RemoteMotor]:
        """The motors of group ``name``."""
        if name not in self._groups:
            known = list(self._groups)
            raise UnknownGroupError(
                f"no group {name!r} (groups: {', '.join(known) or 'none'})",
                motor=str(name),
                known=known,
            )
        return [self._by_name[n] for n in self._groups[name]]

    @property
    def compliant(self) -> bool:
        """True when every motor is compliant; setting it sets every motor."""
        return bool(self._client.get(path_of("robot"))["compliant"])

    @compliant.setter
    def compliant(self, value: bool) -> None:
        self._client.request("PUT", path_of("robot", "compliant"), {"compliant": bool(value)})

    def goto_position(
        self,
        position_for_motors: Mapping[str, float],
        duration: float,
        control: str = "minjerk",
        wait: bool = False,
    ) -> RemoteGoto:
        """Move several motors so that they arrive together (see ``Robot.goto_position``)."""
        return _goto(self._client, position_for_motors, duration, control, wait)

    def state(self) -> dict[str, dict[str, Any]]:
        """Motor name -> present position, speed, load, temperature and LED."""
        answer = self._client.get(path_of("robot", "state"))
        assert isinstance(answer, dict)
        return answer

    def health(self) -> dict[str, dict[str, Any]]:
        """Controller name -> its bus's health as the server sees it (``Robot.health``)."""
        answer = self._client.get(path_of("robot", "health"))
        assert isinstance(answer, dict)
        return answer

    @property
    def primitive_names(self) -> list[str]:
        """Names of the primitives attached on the server."""
        return list(self._client.get(path_of("robot"))["primitives"])

    @property
    def primitives(self) -> list[RemotePrimitive]:
        """The primitives attached on the server."""
        return [RemotePrimitive(self._client, n) for n in self.primitive_names]

    @property
    def active_primitives(self) -> list[RemotePrimitive]:
        """The primitives running (or paused)."""
        described = self._client.get(path_of("primitives"))
        return [RemotePrimitive(self._client, p["name"]) for p in described if p["alive"]]

    def primitive(self, name: str) -> RemotePrimitive:
        """The primitive called ``name``."""
        if name not in self.primitive_names:
            raise UnknownPrimitiveError(
                f"no primitive {name!r} on the server",
                name=str(name),
                known=list(self.primitive_names),
            )
        return RemotePrimitive(self._client, name)

    def camera_names(self) -> list[str]:
        """The names of the served robot's cameras (its sensors of a camera type)."""
        sensors = self._client.get(path_of("sensors"))
        return [str(s["name"]) for s in sensors if str(s.get("type", "")).endswith("Camera")]

    def camera_image(self, camera: str, ext: str = "png") -> bytes:
        """The latest frame of the served robot's camera ``camera`` as a ``png`` or ``jpg``
        file's bytes (the first waits for the camera to start, on the robot's side).

        Raises:
            ConfigError: no such camera, or it is not available (the server's refusal).
            CommunicationError: the server cannot be reached.
        """
        return self._client.image(path_of("sensors", camera, f"frame.{ext}"))

    def close(self) -> None:
        """Close the connections (the served robot keeps running)."""
        self._client.close()

    def __enter__(self) -> RemoteRobot:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _client(
    url: str, token: str | None, timeout_s: float, zenoh: ZenohSettings | None
) -> HttpClient:
    from poppy_core.remote.zenoh_client import ZenohClient, robot_name

    name = robot_name(url)
    if name is None:
        return HttpClient(url, token=token, timeout_s=timeout_s)
    return ZenohClient(name, token=token, timeout_s=timeout_s, settings=zenoh)
