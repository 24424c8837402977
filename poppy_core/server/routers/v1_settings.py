"""v1: the robot's settings (name, Wi-Fi, services, token, version) for the page's panel.

Reading needs what every route needs (the token when the server has one); every change also
needs the server to have been started with ``--token`` and a machine with NetworkManager
(``settings.RobotSettings`` refuses otherwise) and is logged with the client's address.
"""

from collections.abc import Callable
from typing import Any, TypeVar

from fastapi import APIRouter, Request  # noqa: TID253 (the server room is FastAPI's)
from pydantic import BaseModel, Field
from starlette.concurrency import run_in_threadpool

from poppy_core.server.errors import ApiError
from poppy_core.server.schemas import Problem
from poppy_core.server.settings import RobotSettings
from poppy_core.server.settings_os import SystemToolError

router = APIRouter(
    prefix="/settings",
    tags=["settings"],
    responses={
        403: {"model": Problem},
        404: {"model": Problem},
        409: {"model": Problem},
        422: {"model": Problem},
    },
)

T = TypeVar("T")


class NameBody(BaseModel):
    """The robot's new name (the machine's and the mDNS one)."""

    name: str = Field(..., max_length=253, description="one DNS label, e.g. poppy or ergo-2")


class JoinBody(BaseModel):
    """A Wi-Fi network to join."""

    ssid: str = Field(..., max_length=64)
    password: str | None = Field(None, max_length=64, description="none for an open network")


class ForgetBody(BaseModel):
    """A saved Wi-Fi network to forget."""

    name: str = Field(..., max_length=64)


class HotspotBody(BaseModel):
    """The fallback access point, named after the robot."""

    on: bool
    password: str | None = Field(None, max_length=64, description="8 to 63 characters")


class ServiceBody(BaseModel):
    """A service on or off."""

    on: bool


class TokenBody(BaseModel):
    """The new token (the request itself carries the current one)."""

    token: str = Field(..., max_length=128, description="12 to 128 visible ASCII characters")


def _settings(request: Request) -> RobotSettings:
    settings = request.app.state.settings
    assert isinstance(settings, RobotSettings)
    return settings


def _who(request: Request) -> str:
    return request.client.host if request.client is not None else "a client"


async def _os(call: Callable[..., T], *args: Any) -> T:
    """Run an OS-bound call in the thread pool; the tool's failure is a 409 with its line."""
    try:
        return await run_in_threadpool(call, *args)
    except SystemToolError as exc:
        raise ApiError("conflict", str(exc), tip="the OS refused the change") from None


@router.get("", summary="The settings, and whether (and why not) they can be changed here")
async def settings_overview(request: Request) -> dict[str, Any]:
    """Name, hostname, services, token, version; ``editable`` false with a ``reason``."""
    return await _os(_settings(request).overview)


@router.get("/wifi", summary="Wi-Fi networks in range and the saved ones")
async def wifi(request: Request) -> dict[str, Any]:
    """``networks`` (ssid, signal, security, in_use) and ``saved`` (name, priority)."""
    return await _os(_settings(request).wifi)


@router.put("/name", summary="Rename the robot (hostname and mDNS name), no reboot")
async def set_name(body: NameBody, request: Request) -> dict[str, Any]:
    """Answers the name announced (a taken name gets a suffix)."""
    won = await _os(_settings(request).set_name, body.name, _who(request))
    return {"name": won, "host": f"{won}.local"}


@router.post("/wifi/join", summary="Join a Wi-Fi network and remember it")
async def join(body: JoinBody, request: Request) -> dict[str, Any]:
    """The robot may leave the network the page came through: reopen it by its name."""
    await _os(_settings(request).join, body.ssid, body.password, _who(request))
    return {"joined": body.ssid}


@router.post("/wifi/forget", summary="Forget a saved Wi-Fi network")
async def forget(body: ForgetBody, request: Request) -> dict[str, Any]:
    """NetworkManager no longer joins it."""
    await _os(_settings(request).forget, body.name, _who(request))
    return {"forgotten": body.name}


@router.put("/wifi/hotspot", summary="The access point named after the robot, as a fallback")
async def hotspot(body: HotspotBody, request: Request) -> dict[str, Any]:
    """Started by NetworkManager only when no known network answers."""
    ssid = await _os(_settings(request).hotspot, body.on, body.password, _who(request))
    return {"on": body.on, "ssid": ssid}


@router.put("/services/{service}", summary="Start a service, or stop it (until the next boot)")
async def set_service(service: str, body: ServiceBody, request: Request) -> dict[str, Any]:
    """``jupyter`` (poppy-jupyter.service); ``snap`` and ``zmq`` are written in the settings
    file of poppy.service, which restarts (``restarting``: the page reconnects)."""
    restarting = await _os(_settings(request).set_service, service, body.on, _who(request))
    return {"service": service, "on": body.on, "restarting": restarting}


@router.put("/token", summary="Change the token (written in the token file; the server restarts)")
async def set_token(body: TokenBody, request: Request) -> dict[str, Any]:
    """``restarting``: poppy.service restarts with the new token now (else at its next start)."""
    restarting = await _os(_settings(request).set_token, body.token, _who(request))
    return {"changed": True, "restarting": restarting}
