"""``HttpClient``: JSON over HTTP with one keep-alive connection per thread (stdlib only)."""

from __future__ import annotations

import http.client
import json
import threading
from typing import Any
from urllib.parse import quote, unquote, urlsplit

from poppy_core.errors import (
    BusTimeout,
    CommunicationError,
    ConfigError,
    RegisterError,
    UnknownGroupError,
    UnknownMotorError,
    UnknownMoveError,
    UnknownNameError,
    UnknownPrimitiveError,
)

DEFAULT_TIMEOUT_S = 10.0


def path_of(*parts: str) -> str:
    """``/api/v1/a/b`` from URL segments, each quoted."""
    return "/api/v1/" + "/".join(quote(p, safe="") for p in parts)


class HttpClient:
    """Sends requests to a ``poppy serve`` server and turns its errors into poppy errors.

    Args:
        base_url: ``http://host:port`` of the server.
        token: sent as ``Authorization: Bearer <token>`` when set.
        timeout_s: socket timeout of each request.

    Raises:
        ConfigError: a URL that is not ``http://host[:port]``.
    """

    def __init__(
        self, base_url: str, token: str | None = None, timeout_s: float = DEFAULT_TIMEOUT_S
    ) -> None:
        try:
            parts = urlsplit(base_url)
            port = parts.port  # parsed here: raises on a port out of 0-65535
        except ValueError as exc:
            raise ConfigError(
                f"{base_url!r} is not an http://host:port URL ({exc})", field="url"
            ) from None
        if parts.scheme != "http" or not parts.hostname:
            raise ConfigError(f"{base_url!r} is not an http://host:port URL", field="url")
        self.base_url = base_url.rstrip("/")
        self.host = parts.hostname
        self.port = port or 80
        self.prefix = parts.path.rstrip("/")
        self.timeout_s = timeout_s
        self._headers = {"Accept": "application/json"}
        if token:
            self._headers["Authorization"] = f"Bearer {token}"
        self._local = threading.local()
        self._all: list[http.client.HTTPConnection] = []
        self._lock = threading.Lock()

    def _connection(self) -> http.client.HTTPConnection:
        connection: http.client.HTTPConnection | None = getattr(self._local, "connection", None)
        if connection is None:
            connection = http.client.HTTPConnection(self.host, self.port, timeout=self.timeout_s)
            self._local.connection = connection
            with self._lock:
                self._all.append(connection)
        return connection

    def _drop(self) -> None:
        connection = getattr(self._local, "connection", None)
        if connection is not None:
            connection.close()
            self._local.connection = None

    def request(self, method: str, path: str, body: Any = None) -> Any:
        """Send a request and return the decoded JSON answer (None for 204).

        Raises:
            CommunicationError: the server cannot be reached (``BusTimeout`` on a timeout).
            UnknownNameError: a 404: an unknown motor, group, primitive, move... (a ConfigError).
            ConfigError: refused: wrong token, conflict, bad value (the server's message).
            RegisterError: a register value the server refused (422 on a register).
        """
        payload = None if body is None else json.dumps(body).encode()
        headers = dict(self._headers)
        if payload is not None:
            headers["Content-Type"] = "application/json"
        status, data = self._send(method, path, payload, headers)
        return self._decode(method, path, status, data)

    def _send(
        self, method: str, path: str, payload: bytes | None, headers: dict[str, str]
    ) -> tuple[int, bytes]:
        """One request's status and body (an idle keep-alive connection closed: tried again)."""
        for attempt in (1, 2):
            connection = self._connection()
            try:
                connection.request(method, self.prefix + path, payload, headers)
                response = connection.getresponse()
                data = response.read()
                break
            except (http.client.RemoteDisconnected, ConnectionResetError, BrokenPipeError) as exc:
                # The server closed an idle keep-alive connection: retry once on a new one.
                self._drop()
                if attempt == 2:
                    raise CommunicationError(f"{self.base_url}: {exc}", port=self.base_url) from exc
            except TimeoutError as exc:
                self._drop()
                raise BusTimeout(
                    f"{self.base_url}: no answer within {self.timeout_s:g} s", port=self.base_url
                ) from exc
            except OSError as exc:
                self._drop()
                raise CommunicationError(
                    f"cannot reach {self.base_url}: {exc}", port=self.base_url
                ) from exc
        if response.will_close:
            self._drop()
        return response.status, data

    def image(self, path: str) -> bytes:
        """The bytes of a GET of ``path`` answered with an image (a camera's ``frame.png``).

        Raises:
            CommunicationError, BusTimeout, ConfigError: as ``request`` (an unknown camera, a
                camera not available: the server's refusal).
        """
        status, data = self._send("GET", path, None, dict(self._headers))
        if status >= 400:
            self._decode("GET", path, status, data)  # raises the refusal's error
        return data

    def _decode(self, method: str, path: str, status: int, data: bytes) -> Any:
        try:
            decoded = json.loads(data) if data else None
        except (ValueError, RecursionError):  # not JSON (or JSON no one should send)
            decoded = data[:200].decode("utf-8", errors="replace")
            if status < 400:
                raise CommunicationError(
                    f"{self.base_url} is not a poppy server: its answer to {method} {path} is "
                    "not JSON (is `poppy serve --http` running there?)",
                    port=self.base_url,
                ) from None
        if status < 400:
            return decoded
        message = _message(decoded) or f"HTTP {status}"
        where = f"{method} {path}: {message}"
        if status == 401:
            raise ConfigError(f"{self.base_url} refused the token: {message}", field="token")
        if status == 422 and "/registers/" in path:
            raise RegisterError(where, register=path.rsplit("/", 1)[-1])
        if status >= 500:
            raise CommunicationError(f"{self.base_url}: {where}", port=self.base_url)
        unknown = _unknown(path, where) if status == 404 else None
        if unknown is not None:
            raise unknown
        raise ConfigError(where, reason=message)

    def get(self, path: str) -> Any:
        """GET ``path``."""
        return self.request("GET", path)

    def close(self) -> None:
        """Close every connection this client opened."""
        with self._lock:
            connections, self._all = self._all, []
        for connection in connections:
            connection.close()
        self._local = threading.local()


def _message(decoded: Any) -> str:
    if isinstance(decoded, dict):
        detail = decoded.get("detail", decoded.get("error"))
        if isinstance(detail, list):  # a validation error of FastAPI
            return "; ".join(
                str(item.get("msg", item)) for item in detail if isinstance(item, dict)
            )
        return str(detail) if detail is not None else json.dumps(decoded)
    return str(decoded) if decoded else ""


_KINDS = ("motors", "groups", "primitives", "moves")
"""The v1 collections whose 404 is an unknown name (a typed ``UnknownNameError``)."""
_DEEPER = ("registers", "properties", "methods")


def _unknown(path: str, message: str) -> UnknownNameError | None:
    """The typed error of a 404 on ``path`` (``/api/v1/motors/m9``: motor ``m9``); None when
    the path names something deeper (a register, a property) that may be the unknown one."""
    parts = [unquote(p) for p in path.split("?")[0].split("/") if p]
    for index, part in enumerate(parts[:-1]):
        if part in _KINDS:
            if index + 2 < len(parts) and parts[index + 2] in (
                "registers",
                "properties",
                "methods",
            ):
                return None  # /motors/m1/registers/nope: the register may be what is unknown
            name = parts[index + 1]
            if part == "motors":
                return UnknownMotorError(message, motor=name)
            if part == "groups":
                return UnknownGroupError(message, motor=name)
            if part == "primitives":
                return UnknownPrimitiveError(message, name=name)
            return UnknownMoveError(message, name=name)
    return None
