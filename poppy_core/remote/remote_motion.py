"""``RemotePrimitive``, ``RemoteMoves``: a served robot's primitives and move library over HTTP."""

from __future__ import annotations

import builtins
from collections.abc import Sequence
from typing import Any

from poppy_core.errors import ConfigError
from poppy_core.remote.client import HttpClient, path_of


class RemotePrimitive:
    """A primitive attached to the remote robot."""

    def __init__(self, client: HttpClient, name: str) -> None:
        self._client = client
        self.name = name

    def __repr__(self) -> str:
        return f"<RemotePrimitive {self.name}>"

    def _post(self, action: str) -> dict[str, Any]:
        answer = self._client.request("POST", path_of("primitives", self.name, action))
        assert isinstance(answer, dict)
        return answer

    def start(self) -> None:
        """Start (or restart) it."""
        self._post("start")

    def stop(self) -> None:
        """Stop it (the server waits for its thread)."""
        self._post("stop")

    def pause(self) -> None:
        """Pause it."""
        self._post("pause")

    def resume(self) -> None:
        """Resume it."""
        self._post("resume")

    def describe(self) -> dict[str, Any]:
        """State, properties, methods and last error."""
        answer = self._client.get(path_of("primitives", self.name))
        assert isinstance(answer, dict)
        return answer

    @property
    def state(self) -> str:
        """``idle``, ``running``, ``paused``, ``stopped`` or ``failed``."""
        return str(self.describe()["state"])

    def is_alive(self) -> bool:
        """True while it runs (or is paused)."""
        return bool(self.describe()["alive"])

    @property
    def properties(self) -> list[str]:
        """The property names."""
        return list(self.describe()["properties"])

    def get_property(self, name: str) -> Any:
        """A property's value."""
        properties = self.describe()["properties"]
        if name not in properties:
            raise ConfigError(f"{self.name} has no property {name!r}", field=name)
        return properties[name]

    def set_property(self, name: str, value: Any) -> None:
        """Set a property (converted and checked by the server)."""
        path = path_of("primitives", self.name, "properties", name)
        self._client.request("PUT", path, {"value": value})

    def call_method(self, name: str, *args: Any, **kwargs: Any) -> Any:
        """Call a declared method; returns its result."""
        path = path_of("primitives", self.name, "methods", name)
        return self._client.request("POST", path, {"args": list(args), "kwargs": kwargs})["result"]


class RemoteMoves:
    """The server's move library and its recordings and playbacks."""

    def __init__(self, client: HttpClient) -> None:
        self._client = client

    def list(self) -> list[str]:
        """Names of the library's moves."""
        return [entry["name"] for entry in self._client.get(path_of("moves"))]

    def get(self, name: str, positions: bool = False) -> dict[str, Any]:
        """A move: motors, frames, duration (and its positions when asked)."""
        query = "?positions=true" if positions else ""
        answer = self._client.get(path_of("moves", name) + query)
        assert isinstance(answer, dict)
        return answer

    def record(self, name: str, motors: Sequence[str] | None = None) -> None:
        """Start recording ``name`` (every motor by default)."""
        body = {"motors": list(motors) if motors is not None else None}
        self._client.request("POST", path_of("moves", name, "record"), body)

    def save(self, name: str) -> dict[str, Any]:
        """Stop recording ``name`` and save it to the library."""
        answer = self._client.request("POST", path_of("moves", name, "save"))
        assert isinstance(answer, dict)
        return answer

    def play(self, name: str, speed: float = 1.0, backwards: bool = False) -> None:
        """Start playing a library move (a ConfigError while it is playing: stop it first)."""
        body = {"speed": speed, "backwards": backwards}
        self._client.request("POST", path_of("moves", name, "play"), body)

    def stop(self, name: str) -> None:
        """Stop playing ``name``."""
        self._client.request("POST", path_of("moves", name, "stop"))

    def delete(self, name: str) -> None:
        """Delete a library move."""
        self._client.request("DELETE", path_of("moves", name))

    def status(self) -> dict[str, builtins.list[str]]:
        """``{"recording": [...], "playing": [...]}``."""
        answer = self._client.get(path_of("moves", "status"))
        assert isinstance(answer, dict)
        return answer
