"""pypot's IK routes: ``/ik/<chain>/value.json``, ``.../goto.json`` and ``.../rpy.json``.

Shapes as pypot 5.0.2 answers them (pypot/server/httpserver.py, rest.py): positions and x axes
are comma-separated strings rounded to 4 decimals; ``goto.json`` takes ``duration`` and any of
``xyz``, ``rot`` (the tip's x axis), ``rpy`` (radians), ``wait``; ``rpy.json`` reads ``r``,
``p``, ``y`` (pypot reads them from a JSON body on GET; the query string works too). pypot
answers 400 for a missing parameter and 403 when IK fails; an unreachable target is one here.
"""

from typing import Any

from fastapi import APIRouter, Request  # noqa: TID253 (the server room is FastAPI's)
from starlette.concurrency import run_in_threadpool

from poppy_core import checks
from poppy_core.errors import ArgumentError, KinematicsError
from poppy_core.motion.cartesian import RobotChain
from poppy_core.server.chain_lookup import find_chain
from poppy_core.server.deps import Service
from poppy_core.server.errors import ApiError
from poppy_core.server.pypot_json import PypotJSON
from poppy_core.server.routers.common import json_body, truthy, wait_goto
from poppy_core.trajectory import goto_duration

router = APIRouter(tags=["pypot"])

GOTO_TIP = (
    "Parameters are: duration, xyz | rot | rpy, [wait=False]. You can cumulate xyz, rot and rpy "
    'inputs, e.g. {"xyz": "0.1,-0.1,0.12", "duration": 2}'
)
RPY_TIP = 'give r, p, y in radians: {"r": 0, "p": 1.57, "y": 0} or ?r=0&p=1.57&y=0'


def _pypot_vector(values: Any) -> str:
    return ",".join(str(round(float(v), 4)) for v in values)


def _value(chain: RobotChain) -> dict[str, str]:
    pose = chain.pose
    return {"xyz": _pypot_vector(pose[:3, 3]), "rot": _pypot_vector(pose[:3, 0])}


def _numbers(data: dict[str, Any], key: str) -> list[float] | None:
    """``"a,b,c"`` or ``[a, b, c]`` as three finite floats (None when absent)."""
    if key not in data:
        return None
    raw = data[key]
    parts = raw.split(",") if isinstance(raw, str) else raw
    if not isinstance(parts, list) or len(parts) != 3:
        raise ApiError("invalid", f'{key} must be three numbers, e.g. "0.1,0,0.2"', tip=GOTO_TIP)
    try:
        return [checks.number_from(v, key) for v in parts]
    except ArgumentError as exc:
        raise ApiError("invalid", str(exc), tip=GOTO_TIP) from None


@router.get("/ik/{chain}/value.json", summary="Position and x axis of a chain's tip (pypot)")
def ik_value(chain: str, service: Service) -> PypotJSON:
    """``{"xyz": "x,y,z", "rot": "Rx.x,Rx.y,Rx.z"}``."""
    return PypotJSON(_value(find_chain(service.robot, chain)))


@router.post("/ik/{chain}/goto.json", summary="Move a chain's tip (pypot)")
async def ik_goto(chain: str, request: Request, service: Service) -> PypotJSON:
    """Moves every active motor in one goto; answers the tip's pose (after it, with ``wait``)."""
    found = find_chain(service.robot, chain)
    data = await json_body(request, tip=GOTO_TIP)
    if not isinstance(data, dict) or "duration" not in data:
        raise ApiError("invalid", "A 'KeyError' occured. A parameter must be missing", tip=GOTO_TIP)
    try:
        duration = goto_duration(data["duration"])
    except ArgumentError as exc:
        raise ApiError("invalid", str(exc), tip=GOTO_TIP) from None
    xyz, rot, rpy = _numbers(data, "xyz"), _numbers(data, "rot"), _numbers(data, "rpy")
    if xyz is None and rot is None and rpy is None:
        raise ApiError("invalid", "give xyz, rot or rpy", tip=GOTO_TIP)
    orientation: Any = found.rpy_to_rotation_matrix(*rpy) if rpy is not None else rot
    wait = truthy(data.get("wait", False))

    def start() -> Any:
        position = xyz if xyz is not None else found.position
        return found.goto(position, orientation, duration=duration, wait=False)

    try:
        handle = await run_in_threadpool(start)
    except KinematicsError as exc:
        raise ApiError(
            "invalid", f"Cant compute IK for chain '{chain}': {exc}", tip=GOTO_TIP, pypot_status=403
        ) from None
    if wait:
        await wait_goto(handle)
    return PypotJSON(_value(found))


@router.get("/ik/{chain}/rpy.json", summary="Rotation matrix of roll, pitch, yaw (pypot)")
async def ik_rpy(chain: str, request: Request, service: Service) -> PypotJSON:
    """``{"rpy": 3x3}`` of ``r``, ``p``, ``y`` in radians (URDF convention, as ikpy's)."""
    found = find_chain(service.robot, chain)
    data = await json_body(request, default={}, tip=RPY_TIP)
    if not isinstance(data, dict):
        data = {}
    values = {**dict(request.query_params), **data}
    try:
        r, p, y = (checks.number_from(values[k], k) for k in ("r", "p", "y"))
    except (KeyError, ArgumentError):
        raise ApiError("invalid", "r, p and y must be finite numbers", tip=RPY_TIP) from None
    return PypotJSON({"rpy": found.rpy_to_rotation_matrix(r, p, y).tolist()})
