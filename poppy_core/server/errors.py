"""API errors of the server and their translation to JSON responses, in one place.

Routes raise ``ApiError`` (or let a ``PoppyError`` through); the handlers installed by
``install_error_handlers`` answer ``{"error", "tip", "details"}`` on pypot's routes (with pypot's
status codes and content type) and ``{"detail"}`` on the v1 API (404 unknown, 409 conflict, 422
invalid value).
"""

from __future__ import annotations

import logging
import math
from typing import TYPE_CHECKING, Any, Literal

from starlette.requests import Request
from starlette.responses import JSONResponse, Response

from poppy_core.errors import (
    ArgumentError,
    BusError,
    BusTimeout,
    ConfigError,
    FileError,
    MissingExtraError,
    MotorError,
    MotorLeasedError,
    PoppyError,
    RegisterError,
    RobotClosedError,
    SensorError,
    UnknownNameError,
)
from poppy_core.server.pypot_json import PypotJSON
from poppy_core.server.refusals import one_line

if TYPE_CHECKING:
    from fastapi import FastAPI

logger = logging.getLogger(__name__)

Kind = Literal["not_found", "invalid", "conflict", "unavailable", "storage", "forbidden"]

V1_PREFIX = "/api/v1"

V1_STATUS: dict[Kind, int] = {
    "not_found": 404,
    "invalid": 422,
    "conflict": 409,
    "unavailable": 503,
    "storage": 507,
    "forbidden": 403,
}
"""HTTP status of each kind of error on the v1 API."""

PYPOT_STATUS: dict[Kind, int] = {
    "not_found": 404,
    "invalid": 400,
    "conflict": 404,
    "unavailable": 503,
    "storage": 507,
    "forbidden": 403,
}
"""HTTP status of each kind on pypot's routes (pypot answers 404 for most refusals)."""


class ListenError(PoppyError):
    """A server cannot listen: a busy port, a name that does not resolve, a refused permission."""


class ApiError(Exception):
    """A request the server refuses.

    Args:
        kind: ``"not_found"``, ``"invalid"``, ``"conflict"``, ``"unavailable"``, ``"storage"``
            (507: the server could not save a file; what was to be saved is kept) or
            ``"forbidden"`` (403: allowed on no request to this server, e.g. settings without
            a token).
        message: what went wrong (the ``error``/``detail`` text).
        tip: how to do it right (pypot's ``tip``).
        pypot_status: the status pypot's route answers, when it differs from ``PYPOT_STATUS``.
    """

    def __init__(
        self, kind: Kind, message: str, *, tip: str = "", pypot_status: int | None = None
    ) -> None:
        super().__init__(message)
        self.kind: Kind = kind
        self.message = message
        self.tip = tip
        self.pypot_status = pypot_status


def pypot_body(error: str, tip: str = "", details: str = "") -> dict[str, str]:
    """pypot's error body."""
    return {"error": error, "tip": tip, "details": details}


def error_response(request: Request, error: ApiError) -> JSONResponse:
    """The response for ``error`` in the style of the route that raised it (one line each)."""
    message = one_line(error.message)
    if request.url.path.startswith(V1_PREFIX):
        return JSONResponse({"detail": message}, status_code=V1_STATUS[error.kind])
    status = error.pypot_status or PYPOT_STATUS[error.kind]
    return PypotJSON(pypot_body(message, one_line(error.tip), message), status_code=status)


NAME_TIPS: dict[str, str] = {
    "motor": "the motors are listed by /motors/list.json",
    "group": "the groups are listed by /motors/aliases/list.json",
    "primitive": "the primitives are listed by /primitives/list.json",
    "move": "the moves are listed by /records/list.json",
    "card": "a card is a name the marker detector knows (caribou, tetris, lapin) or an id",
}
"""How to find the right name, for each ``UnknownNameError.kind``."""


def from_poppy_error(exc: PoppyError) -> ApiError:
    """Translate a core error by its TYPE (never its text).

    ``UnknownNameError`` (motor, group, primitive, move, card) is ``not_found``; an
    ``ArgumentError``, ``RegisterError`` or other ``ConfigError`` is ``invalid``; bus trouble,
    a closed robot, a sensor that does not answer or a feature whose extra is not installed is
    ``unavailable``; a file is ``storage``; a motor another owner drives is ``conflict``.
    """
    if isinstance(exc, UnknownNameError):
        return ApiError("not_found", str(exc), tip=NAME_TIPS.get(exc.kind, ""))
    if isinstance(exc, ArgumentError | RegisterError | ConfigError):
        return ApiError("invalid", str(exc))
    if isinstance(exc, BusTimeout | BusError | MotorError):
        return ApiError("unavailable", f"the robot did not answer: {exc}")
    if isinstance(exc, SensorError | MissingExtraError):  # a sensor without its extra too
        return ApiError("unavailable", str(exc))
    if isinstance(exc, RobotClosedError):
        return ApiError("unavailable", str(exc))
    if isinstance(exc, FileError):
        return ApiError("storage", str(exc))
    if isinstance(exc, MotorLeasedError):
        return ApiError("conflict", str(exc))
    return ApiError("invalid", str(exc))


def refusal_kind(exc: BaseException) -> Kind:
    """The kind of a refusal, for the surfaces that answer without a status (WebSocket frames
    and ZMQ replies carry it as ``"kind"``): an ``ApiError``'s own, a core error's by its type,
    and ``"invalid"`` for a bad argument Python itself refused (``ValueError``, ``TypeError``).
    """
    if isinstance(exc, ApiError):
        return exc.kind
    if isinstance(exc, PoppyError):
        return from_poppy_error(exc).kind
    return "invalid"


async def _api_error(request: Request, exc: Exception) -> Response:
    assert isinstance(exc, ApiError)
    return error_response(request, exc)


async def _poppy_error(request: Request, exc: Exception) -> Response:
    assert isinstance(exc, PoppyError)
    logger.info("%s %s refused: %s", request.method, request.url.path, exc)
    return error_response(request, from_poppy_error(exc))


def encodable(value: Any) -> Any:
    """``value`` with every non-finite float as text (``"nan"``, ``"inf"``): JSON has none."""
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    if isinstance(value, dict):
        return {str(k): encodable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [encodable(v) for v in value]
    return value


async def _invalid_request(request: Request, exc: Exception) -> Response:
    # FastAPI's own handler echoes the input: NaN or 1e309 in a body made it fail (a 500).
    from fastapi.encoders import jsonable_encoder
    from fastapi.exceptions import RequestValidationError

    assert isinstance(exc, RequestValidationError)
    return JSONResponse({"detail": encodable(jsonable_encoder(exc.errors()))}, status_code=422)


async def _bug(request: Request, exc: Exception) -> Response:
    # uvicorn logs the traceback server-side; the client gets one line without paths.
    message = f"internal error ({type(exc).__name__}): the server's log has the details"
    if request.url.path.startswith(V1_PREFIX):
        return JSONResponse({"detail": message}, status_code=500)
    tip = "this is a bug in poppy: please report it with the server's log"
    return PypotJSON(pypot_body(message, tip), status_code=500)


def install_error_handlers(app: FastAPI) -> None:
    """Map ``ApiError`` and ``PoppyError`` to JSON answers on ``app``, and bugs to a bare 500."""
    from fastapi.exceptions import RequestValidationError

    app.add_exception_handler(RequestValidationError, _invalid_request)
    app.add_exception_handler(ApiError, _api_error)
    app.add_exception_handler(PoppyError, _poppy_error)
    app.add_exception_handler(Exception, _bug)
