"""v1: the robot as a whole (description, state, compliance) and its groups."""

from fastapi import APIRouter  # noqa: TID253 (the server room is FastAPI's)

from poppy_core.server.deps import Service
from poppy_core.server.schemas import BusHealthInfo, CompliantBody, Problem, RobotInfo
from poppy_core.server.values import STATE_REGISTERS

router = APIRouter(tags=["robot"], responses={404: {"model": Problem}, 422: {"model": Problem}})


def _info(service: Service) -> RobotInfo:
    return RobotInfo(
        motors=service.motor_names(),
        groups=service.groups(),
        primitives=list(service.primitives()),
        compliant=service.robot.compliant,
    )


@router.get("/robot", summary="The robot's motors, groups and primitives")
async def robot_info(service: Service) -> RobotInfo:
    """Names of everything the robot offers."""
    return _info(service)


@router.get("/robot/state", summary=f"Every motor's {', '.join(STATE_REGISTERS)}")
async def robot_state(service: Service) -> dict[str, dict[str, float | bool | str | None]]:
    """Motor name -> its present state (what the WebSocket streams)."""
    return service.state()


@router.get("/robot/health", summary="Each bus: connected, loop rates, errors, offline motors")
async def robot_health(service: Service) -> dict[str, BusHealthInfo]:
    """Controller name -> its bus's health; a lost bus is reopened by the robot on its own."""
    return {name: BusHealthInfo(**data) for name, data in service.health().items()}


@router.put("/robot/compliant", summary="Make every motor compliant or stiff")
async def set_compliant(body: CompliantBody, service: Service) -> RobotInfo:
    """Sets every motor, then describes the robot."""
    service.set_compliant(body.compliant)
    return _info(service)


@router.get("/teleop", summary="Motors teleoperated over the WebSocket and their state")
async def teleop_state(service: Service) -> dict[str, str]:
    """Motor name -> ``ramping``, ``following``, ``held``... (empty when none)."""
    return service.teleop.states()


@router.get("/groups", summary="Group name -> its motors")
async def groups(service: Service) -> dict[str, list[str]]:
    """Every motor group."""
    return service.groups()


@router.get("/groups/{group}", summary="The motors of a group")
async def group(group: str, service: Service) -> list[str]:
    """Motor names of ``group``."""
    return service.group(group)
