"""Pydantic bodies and answers of the v1 API (they make the OpenAPI schema)."""

from typing import Annotated

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, JsonValue

from poppy_core import checks
from poppy_core.motion.play_plan import MAX_SPEED, MIN_SPEED
from poppy_core.trajectory import CONTROLS, control_name

Finite = Annotated[float, Field(allow_inf_nan=False)]
MotorName = Annotated[str, Field(min_length=1, max_length=64)]


class Problem(BaseModel):
    """An error: what went wrong."""

    detail: str


class RobotInfo(BaseModel):
    """The robot: its motors, groups and primitives."""

    motors: list[str]
    groups: dict[str, list[str]]
    primitives: list[str]
    compliant: bool


class BusHealthInfo(BaseModel):
    """One bus's health (``Robot.health()``): is it there, how fast its loops run, what fails."""

    controller: str
    port: str
    ok: bool = Field(description="connected, running, and every motor answering")
    connected: bool = Field(description="false while the port is lost; it is reopened")
    running: bool = Field(description="the sync thread is alive")
    down_s: float = Field(description="seconds since the port was lost (0 when connected)")
    losses: int = Field(description="times the port was lost")
    loop_hz: dict[str, float] = Field(description="loop name -> rate measured now")
    target_hz: dict[str, float] = Field(description="loop name -> rate asked for")
    loop_errors: int
    timeouts: int
    retries: int
    corrupt_packets: int
    motor_errors: int
    offline: list[str] = Field(description="motors that do not answer (retried)")


class CompliantBody(BaseModel):
    """Compliance of the whole robot."""

    model_config = ConfigDict(extra="forbid")
    compliant: bool


class MotorInfo(BaseModel):
    """One motor and its registers (SI units, user frame)."""

    name: str
    id: int
    model: str
    online: bool
    errors: int = Field(description="failed reads so far")
    registers: dict[str, JsonValue]
    owner: str | None = Field(
        None,
        description="who drives its goal (``teleop from 192.168.1.20``, ``move wave from "
        "127.0.0.1``, ``trajectory from ROS 2``, ``primitive sinus``): the v1 API, Zenoh and "
        "ROS 2 goals for it are refused (409) until it ends; null when none",
    )


class RegisterValue(BaseModel):
    """One register of one motor."""

    model_config = ConfigDict(populate_by_name=True)
    motor: str
    register_name: str = Field(alias="register")
    value: JsonValue


class ValueBody(BaseModel):
    """A value to write."""

    model_config = ConfigDict(extra="forbid")
    value: JsonValue


GOTO_DURATION = (
    "seconds the motion lasts: 0 (at once) or "
    f"{checks.MIN_DURATION_S:g}-{checks.MAX_DURATION_S:g} (the library's rule)"
)


class GotoRequest(BaseModel):
    """Move motors so that they arrive together."""

    model_config = ConfigDict(extra="forbid")
    positions: dict[MotorName, Finite] = Field(
        min_length=1, max_length=64, description="motor name -> target in degrees"
    )
    duration_s: Annotated[Finite, AfterValidator(lambda v: checks.duration(v, "duration_s"))] = (
        Field(ge=0, le=checks.MAX_DURATION_S, description=GOTO_DURATION)
    )
    control: Annotated[str, AfterValidator(control_name)] = Field(
        "minjerk", description=f"one of {', '.join(CONTROLS)} ('minijerk' is 'minjerk')"
    )
    wait: bool = Field(False, description="answer once the motion is over")


class GotoResult(BaseModel):
    """A goto that started (and, with ``wait``, ended)."""

    positions: dict[str, float]
    duration_s: float
    control: str
    waited: bool
    done: bool


class PrimitiveInfo(BaseModel):
    """A primitive: state, properties, methods, last error."""

    model_config = ConfigDict(populate_by_name=True)
    name: str
    class_name: str = Field(alias="class")
    state: str
    alive: bool
    elapsed_s: float
    properties: dict[str, JsonValue]
    methods: list[str]
    error: dict[str, str] | None


class MethodCall(BaseModel):
    """Arguments of a primitive method."""

    model_config = ConfigDict(extra="forbid")
    args: list[JsonValue] = Field(default_factory=list, max_length=32)
    kwargs: dict[str, JsonValue] = Field(default_factory=dict, max_length=32)


class MethodResult(BaseModel):
    """What a primitive method returned."""

    result: JsonValue


class LibraryMoveInfo(BaseModel):
    """A move of the library."""

    name: str
    format: str
    size_bytes: int
    duration_s: float | None = Field(
        None, description="seconds from the first frame to the last (null: unreadable file)"
    )
    frames: int | None = Field(None, description="frames (null: unreadable file)")


class MoveInfo(BaseModel):
    """A move: its motors, frames and (on request) positions in degrees."""

    name: str
    framerate: float
    motors: list[str]
    frames: int
    duration_s: float
    positions: list[list[float]] | None = None


class RecordRequest(BaseModel):
    """What to record (every motor when ``motors`` is null)."""

    model_config = ConfigDict(extra="forbid")
    motors: list[MotorName] | None = Field(None, max_length=64)


START_AT = (
    "the wall-clock time (seconds since 1970, within a minute of now) the start is armed for: "
    "checked and made now, started then (null: now); a stop before it calls it off"
)


class PlayRequest(BaseModel):
    """How to play a move."""

    model_config = ConfigDict(extra="forbid")
    speed: Finite = Field(
        1.0, ge=MIN_SPEED, le=MAX_SPEED, description="2.0 plays twice as fast (the player's range)"
    )
    backwards: bool = False
    ramp_s: Finite | None = Field(
        None,
        ge=0,
        le=checks.MAX_DURATION_S,
        description="seconds of the ramp to the first frame (null: from the distance); the "
        "same on every robot of a fleet keeps them in phase",
    )
    start_at: Finite | None = Field(None, description=START_AT)


class StartRequest(BaseModel):
    """When to start (a fleet's shared start): nothing, or a ``start_at``."""

    model_config = ConfigDict(extra="forbid")
    start_at: Finite | None = Field(None, description=START_AT)


class MovesStatus(BaseModel):
    """Moves being recorded and played."""

    recording: list[str]
    playing: list[str]
