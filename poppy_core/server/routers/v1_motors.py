"""v1: motors and their registers (read, write one, write many at once)."""

from typing import Any

from fastapi import APIRouter, Body  # noqa: TID253 (the server room is FastAPI's)
from pydantic import JsonValue

from poppy_core.server.deps import Service
from poppy_core.server.routers.common import V1_WRITER
from poppy_core.server.schemas import MotorInfo, Problem, RegisterValue, ValueBody
from poppy_core.server.values import motor_registers

router = APIRouter(tags=["motors"], responses={404: {"model": Problem}, 422: {"model": Problem}})


def _info(service: Service, name: str, owners: dict[str, str] | None = None) -> MotorInfo:
    motor = service.motor(name)
    if owners is None:
        owners = service.leases.labels()
    return MotorInfo(
        name=motor.name,
        id=motor.id,
        model=motor.model.name,
        online=motor.online,
        errors=motor.errors,
        registers=motor_registers(motor),
        owner=owners.get(motor.name),
    )


@router.get("/motors", summary="Every motor and its registers")
async def motors(service: Service) -> list[MotorInfo]:
    """The motors in config order."""
    owners = service.leases.labels()
    return [_info(service, name, owners) for name in service.motor_names()]


@router.patch("/motors", summary="Write registers of several motors (all or nothing)")
async def write_many(
    service: Service,
    commands: dict[str, dict[str, JsonValue]] = Body(  # noqa: B008 (FastAPI's idiom)
        ..., examples=[{"m1": {"goal_position": 20, "led": "green"}}]
    ),
) -> dict[str, dict[str, JsonValue]]:
    """Every value is checked before any is written; answers the values written."""
    written: dict[str, dict[str, Any]] = service.write_many(
        commands, refuse_compliant=True, writer=V1_WRITER
    )
    return written


@router.get("/motors/{motor}", summary="One motor and its registers")
async def motor(motor: str, service: Service) -> MotorInfo:
    """Its id, model and register values."""
    return _info(service, motor)


@router.get("/motors/{motor}/registers", summary="The registers of a motor and their values")
async def registers(motor: str, service: Service) -> dict[str, JsonValue]:
    """Register name -> value."""
    return motor_registers(service.motor(motor))


@router.get("/motors/{motor}/registers/{register}", summary="Read a register")
async def read_register(motor: str, register: str, service: Service) -> RegisterValue:
    """The register's value."""
    return RegisterValue(motor=motor, register=register, value=service.read(motor, register))


@router.put("/motors/{motor}/registers/{register}", summary="Write a register")
async def write_register(
    motor: str, register: str, body: ValueBody, service: Service
) -> RegisterValue:
    """Checks the value (type, range, limits) before the motor gets it."""
    value = service.write(motor, register, body.value, refuse_compliant=True, writer=V1_WRITER)
    return RegisterValue(motor=motor, register=register, value=value)


@router.get("/registers/{register}", summary="One register of every motor")
async def register_values(register: str, service: Service) -> dict[str, JsonValue]:
    """Motor name -> value."""
    return service.register_values(register)
