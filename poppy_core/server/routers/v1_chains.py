"""v1: kinematic chains (tip pose, forward kinematics, solve, cartesian gotos)."""

from functools import partial
from typing import Annotated, Any

from fastapi import APIRouter  # noqa: TID253 (the server room is FastAPI's)
from pydantic import BaseModel, ConfigDict, Field, model_validator
from starlette.concurrency import run_in_threadpool
from starlette.requests import Request

from poppy_core.checks import MAX_DURATION_S
from poppy_core.kinematics import rotation_degrees
from poppy_core.server.chain_lookup import chain_state, find_chain
from poppy_core.server.deps import Service
from poppy_core.server.routers.common import client_of, wait_goto
from poppy_core.server.schemas import Problem

router = APIRouter(tags=["chains"], responses={404: {"model": Problem}, 422: {"model": Problem}})

Finite = Annotated[float, Field(allow_inf_nan=False)]
Vector = Annotated[list[Finite], Field(min_length=3, max_length=3)]


class ChainInfo(BaseModel):
    """A chain: its motors and where its tip is (metres, in the chain's base frame)."""

    name: str
    label: str = Field(description="the name people are shown (the Ergo Jr's chain: arm)")
    motors: list[str]
    active_motors: list[str] = Field(description="the motors solves and gotos move")
    base: str = Field(description="the link positions are expressed in")
    position: list[float]
    orientation: list[float] = Field(description="the tip's x axis (pypot's orientation)")
    rpy_deg: list[float] = Field(description="roll, pitch, yaw of the tip (degrees)")
    pose: list[list[float]] = Field(description="4x4 transform of the tip")


class TipTarget(BaseModel):
    """Where the tip must go: a position, and optionally its x axis or its roll/pitch/yaw."""

    model_config = ConfigDict(extra="forbid")
    position: Vector = Field(description="metres, in the chain's base frame")
    orientation: Vector | None = Field(None, description="the tip's x axis (pypot's vector)")
    rpy_deg: Vector | None = Field(None, description="the tip's roll, pitch, yaw in degrees")

    @model_validator(mode="after")
    def _one_orientation(self) -> "TipTarget":
        if self.orientation is not None and self.rpy_deg is not None:
            raise ValueError("give orientation or rpy_deg, not both")
        return self

    def goal(self) -> Any:
        """The orientation the solver takes (None, a vector or a rotation matrix)."""
        return rotation_degrees(self.rpy_deg) if self.rpy_deg is not None else self.orientation


class SolveBody(TipTarget):
    """A target and, optionally, the angles to start from (degrees; default: present)."""

    seed: dict[str, Finite] | None = None


class GotoBody(TipTarget):
    """A target and how to get there."""

    duration: Annotated[float, Field(gt=0, le=MAX_DURATION_S)] = 1.0
    wait: bool = False
    linear: bool = Field(False, description="move the tip along a straight line")


class ForwardBody(BaseModel):
    """Joint angles (degrees) of some of the chain's motors; the others where they are."""

    model_config = ConfigDict(extra="forbid")
    joints: dict[str, Finite]


class SolveAnswer(BaseModel):
    """The active motors' angles (degrees) that bring the tip to the target."""

    chain: str
    angles: dict[str, float]


class GotoAnswer(SolveAnswer):
    """The angles the motors go to; with ``wait``, where the tip ended."""

    duration: float
    waited: bool
    position: list[float]


class Pose(BaseModel):
    """A tip pose."""

    position: list[float]
    orientation: list[float]
    pose: list[list[float]]


@router.get("/chains", summary="The robot's kinematic chains and their tips")
async def chains(service: Service) -> list[ChainInfo]:
    """Every chain (empty for a robot whose config describes none)."""
    from poppy_core.motion.chains import robot_chains

    return [ChainInfo(**chain_state(c)) for c in robot_chains(service.robot).values()]


@router.get("/chains/{chain}", summary="A chain and where its tip is")
async def chain(chain: str, service: Service) -> ChainInfo:
    """Its motors, tip position, x axis, roll/pitch/yaw and 4x4 pose."""
    return ChainInfo(**chain_state(find_chain(service.robot, chain)))


@router.post("/chains/{chain}/forward", summary="Where the tip would be for some angles")
async def forward(chain: str, body: ForwardBody, service: Service) -> Pose:
    """Forward kinematics; motors not given are taken where they are."""
    pose = find_chain(service.robot, chain).forward(body.joints)
    return Pose(position=pose[:3, 3].tolist(), orientation=pose[:3, 0].tolist(), pose=pose.tolist())


@router.post("/chains/{chain}/solve", summary="Angles that bring the tip to a target")
async def solve(chain: str, body: SolveBody, service: Service) -> SolveAnswer:
    """Nothing moves. 422 when out of reach, naming the nearest point."""
    found = find_chain(service.robot, chain)
    angles = await run_in_threadpool(found.solve, body.position, body.goal(), body.seed)
    return SolveAnswer(chain=chain, angles=angles)


@router.post(
    "/chains/{chain}/goto",
    summary="Move the tip to a target",
    responses={409: {"model": Problem}},
)
async def goto(chain: str, body: GotoBody, service: Service, request: Request) -> GotoAnswer:
    """Every active motor in one goto (or along a straight line with ``linear``). A motor
    another owner drives (a move, a teleoperation...) or a compliant one refuses it (409, as
    ``POST /api/v1/gotos`` does); while it runs, it
    drives its motors (``chain arm goto from ADDRESS``): other v1 goals for them are refused."""
    found = find_chain(service.robot, chain)
    angles, handle = await run_in_threadpool(
        partial(service.chain_goto, linear=body.linear, client=client_of(request)),
        found,
        body.position,
        body.goal(),
        body.duration,
    )
    if body.wait:
        await wait_goto(handle)
    return GotoAnswer(
        chain=chain,
        angles=angles,
        duration=body.duration,
        waited=body.wait,
        position=found.position.tolist(),
    )
