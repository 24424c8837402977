"""Dependencies of the routes: the ``RobotService`` of the app serving the request."""

from typing import Annotated

from fastapi import Depends, Request  # noqa: TID253 (the server room is FastAPI's; loaded lazily)

from poppy_core.server.service import RobotService


async def get_service(request: Request) -> RobotService:
    """The service ``create_app`` stored on the app (async: no thread-pool hop)."""
    service = request.app.state.service
    assert isinstance(service, RobotService)
    return service


Service = Annotated[RobotService, Depends(get_service)]
"""A route parameter receiving the robot service."""
