"""``RobotService``: what the routes do to a robot, shared by pypot's routes, v1 and the stream.

Every method is cheap and thread-safe except ``stop_primitive`` (it joins a thread): routes call
those from the thread pool. Gotos never block here: the caller awaits the returned handle.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Hashable, Mapping, Sequence
from typing import Any

from poppy_core.kinematics.chain import Orientation
from poppy_core.kinematics.transforms import Vector
from poppy_core.motion import attach_builtins
from poppy_core.motion.cartesian import RobotChain
from poppy_core.motion.leases import Lease, motor_leases
from poppy_core.motion.play_plan import write_rate_hz
from poppy_core.motion.waypoints import WaypointFollower, Waypoints
from poppy_core.robot import GotoHandle, Motor, Robot
from poppy_core.server import values
from poppy_core.server.chain_gotos import ChainGotos, ChainMove, chain_holder
from poppy_core.server.compliant_goals import GOAL_REGISTERS, CompliantGoals, goal_motors
from poppy_core.server.errors import ApiError
from poppy_core.server.moves import MoveService
from poppy_core.server.recordings import DatasetRecordings
from poppy_core.server.service_primitives import PrimitiveOperations
from poppy_core.server.start_time import StartTimes, check_start_at, on_monotonic
from poppy_core.server.teleop_channel import TeleopRegistry
from poppy_core.trajectory import control_name, goto_duration

logger = logging.getLogger(__name__)


class RobotService(PrimitiveOperations):
    """The robot as the server sees it.

    Args:
        robot: the robot served (the caller owns it and closes it).
        builtins: attach the built-in primitives (sinus, square, ...) not yet attached.
    """

    def __init__(self, robot: Robot, *, builtins: bool = True) -> None:
        self.robot = robot
        if builtins:
            attach_builtins(robot)
        self.starts = StartTimes()
        """The starts armed for a shared start time (``start_at``)."""
        self.leases = motor_leases(robot)
        """Who drives each motor's goal (``motion/leases.py``): strict writers are checked."""
        self.moves = MoveService(robot, self.starts, self.leases)
        self.follower = WaypointFollower(robot, write_rate_hz(robot), "trajectory")
        """The trajectory followed (``follow``): one at a time, the next replaces it."""
        self.teleop = TeleopRegistry(self.leases)
        """Which WebSocket connection teleoperates which motor (a lease each)."""
        self.chain_gotos = ChainGotos(self.leases)
        """The v1 chain gotos running (a lease each)."""
        self.recordings = DatasetRecordings(robot, self.moves, self.leases)
        """The LeRobot dataset recorded from the page (one at a time)."""
        self._description: tuple[float, bytes] | None = None
        self.compliant_goals = CompliantGoals()
        """Goals to compliant motors: refused on v1, logged once per motor either way."""

    # -- motors and groups ---------------------------------------------------------------------

    def motor(self, name: str) -> Motor:
        """The motor ``name`` (``UnknownMotorError``, a 404, for another name)."""
        return self.robot.motor(name)

    def motor_names(self) -> list[str]:
        """Every motor name, in config order."""
        return [m.name for m in self.robot.motors]

    def groups(self) -> dict[str, list[str]]:
        """Group name -> motor names."""
        return {g: [m.name for m in ms] for g, ms in self.robot.motorgroups.items()}

    def group(self, name: str) -> list[str]:
        """The motor names of group ``name`` (``"motors"`` is every motor, as in pypot)."""
        if name == "motors":
            return self.motor_names()
        groups = self.groups()
        if name not in groups:
            known = ", ".join(groups) or "none"
            raise ApiError(
                "not_found",
                f"no group {name!r} (groups: {known})",
                tip="the groups are listed by /motors/aliases/list.json",
            )
        return groups[name]

    def read(self, motor: str, register: str) -> Any:
        """The JSON value of a register."""
        return values.read_register(self.motor(motor), register)

    def write(
        self,
        motor: str,
        register: str,
        value: Any,
        *,
        refuse_compliant: bool = False,
        writer: Hashable | None = None,
    ) -> Any:
        """Check then write a register; returns the value written.

        ``writer``: who writes, for a strict surface (v1, Zenoh, ROS 2): a goal for a motor
        another owner leases is refused. None: pypot's plain write (last write wins).

        Raises:
            CompliantMotorError: with ``refuse_compliant`` (the v1 API), a goal to a compliant
                motor (written otherwise, as pypot does, and logged once).
            MotorLeasedError: with a ``writer``, a goal for a motor another owner drives.
        """
        found = self.motor(motor)
        checked = values.check_write(found, register, value)
        if register in GOAL_REGISTERS:
            self._goals([found], refuse_compliant, writer)
        values.apply_checked(found, register, checked)
        if register == "compliant" and checked is False:
            self.compliant_goals.stiff([found.name])
        return values.jsonable(checked)

    def _goals(
        self, motors: Sequence[Motor], refuse_compliant: bool, writer: Hashable | None = None
    ) -> None:
        """Goals for ``motors``: refused when another owner leases one (``writer`` given: a
        strict surface) or when one is compliant and ``refuse_compliant``, else noted (the log
        names a compliant motor once)."""
        if writer is not None:
            self.leases.check([m.name for m in motors], writer)
        if refuse_compliant:
            self.compliant_goals.refuse(motors)
        for motor in motors:
            self.compliant_goals.note(motor)

    def write_many(
        self, commands: Any, *, refuse_compliant: bool = False, writer: Hashable | None = None
    ) -> dict[str, dict[str, Any]]:
        """Apply ``{motor: {register: value}}`` after checking every value (all or nothing).

        Raises:
            CompliantMotorError: with ``refuse_compliant``, a goal to a compliant motor that the
                same command does not make stiff (nothing is written then).
            MotorLeasedError: with a ``writer`` (as ``write``), a goal for a motor another
                owner drives (nothing is written then).
        """
        if not isinstance(commands, Mapping):
            raise ApiError("invalid", "expected an object {motor: {register: value}}")
        checked: list[tuple[Motor, str, Any]] = []
        for motor_name, registers in commands.items():
            motor = self.motor(str(motor_name))
            if not isinstance(registers, Mapping):
                raise ApiError("invalid", f"{motor_name}: expected an object {{register: value}}")
            for register, value in registers.items():
                checked.append(
                    (motor, str(register), values.check_write(motor, str(register), value))
                )
        self._goals([self.motor(str(m)) for m in goal_motors(commands)], refuse_compliant, writer)
        out: dict[str, dict[str, Any]] = {}
        for motor, register, value in checked:
            values.apply_checked(motor, register, value)
            out.setdefault(motor.name, {})[register] = values.jsonable(value)
            if register == "compliant" and value is False:
                self.compliant_goals.stiff([motor.name])
        return out

    def register_values(self, register: str) -> dict[str, Any]:
        """Motor name -> the value of ``register`` (every motor must have it)."""
        return {m.name: values.read_register(m, register) for m in self.robot.motors}

    def state(self) -> dict[str, dict[str, Any]]:
        """Motor name -> its streamed state."""
        return {m.name: values.motor_state(m) for m in self.robot.motors}

    def health(self) -> dict[str, dict[str, Any]]:
        """Controller name -> its bus's health (``BusHealth.as_dict``)."""
        return {name: health.as_dict() for name, health in self.robot.health().items()}

    def set_compliant(self, compliant: bool) -> None:
        """Make every motor compliant or stiff."""
        self.robot.compliant = compliant
        if not compliant:
            self.compliant_goals.stiff(self.motor_names())

    # -- gotos ---------------------------------------------------------------------------------

    def goto(
        self,
        positions: Mapping[str, Any],
        duration_s: Any,
        control: str = "minjerk",
        *,
        refuse_compliant: bool = False,
        writer: Hashable | None = None,
    ) -> GotoHandle:
        """Start a goto of several motors after checking every target and the duration.

        The rules are the library's (``trajectory.goto_duration``, ``control_name``); a target
        outside a motor's angle limits is clamped to them, as ``Motor.goal_position`` does.

        Raises:
            UnknownMotorError: an unknown motor.
            ArgumentError: a target that is not a finite number, a bad duration or control.
            ApiError: no motor.
            CompliantMotorError: with ``refuse_compliant`` (the v1 API), a compliant motor (it
                would not move; pypot's routes start the goto, and the log names it once).
            MotorLeasedError: with a ``writer`` (as ``write``), a motor another owner drives.
        """
        duration = goto_duration(duration_s)
        control = control_name(control)
        targets = self.targets(positions)
        self._goals([self.motor(name) for name in targets], refuse_compliant, writer)
        return self.robot.goto_position(targets, duration, control=control, wait=False)

    def targets(self, positions: Mapping[str, Any]) -> dict[str, float]:
        """Motor name -> goal checked and clamped to its angle limits (what a goto will aim at).

        Raises:
            UnknownMotorError: an unknown motor.
            ApiError: no motor, or a goal that is not a finite number.
        """
        if not positions:
            raise ApiError("invalid", "no motor to move")
        return {
            name: values.check_position(self.motor(name), "goal_position", value)
            for name, value in positions.items()
        }

    def set_goals(
        self,
        positions: Mapping[str, Any],
        *,
        refuse_compliant: bool = False,
        replace_trajectory: bool = False,
        writer: Hashable | None = None,
        lease: Lease | None = None,
    ) -> dict[str, float]:
        """Check every goal (``targets``: the limit rule), then set them all (or none).

        Args:
            positions: motor name -> degrees.
            refuse_compliant: refuse a goal to a compliant motor (v1's rule, ROS 2's).
            replace_trajectory: the goals end the trajectory followed (ROS 2's joint command).
            writer: who writes (a strict surface, as ``write``); None: pypot's plain write.
            lease: a goal stream's lease, taken (or kept) for these motors (Zenoh's goals):
                its holder is the writer.

        Raises:
            UnknownMotorError: an unknown motor (nothing moved).
            ApiError: no motor, or a goal that is not a finite number (nothing moved).
            CompliantMotorError: with ``refuse_compliant``, a compliant motor (nothing moved).
            MotorLeasedError: a motor another owner drives (nothing moved).
        """
        targets = self.targets(positions)
        motors = [self.motor(name) for name in targets]
        self._goals(motors, refuse_compliant, writer)
        if lease is not None:
            self.leases.take(lease, list(targets))
            lease.touch()
        if replace_trajectory:
            self.follower.stop()
        for motor in motors:
            motor.goal_position = targets[motor.name]
        return targets

    def follow(
        self,
        motors: Sequence[str],
        times: Sequence[float],
        points: Sequence[Sequence[Any]],
        *,
        start_at: float | None = None,
        refuse_compliant: bool = True,
        writer: Hashable | None = None,
        client: str = "",
    ) -> Waypoints | None:
        """Follow a trajectory (replacing the one followed): ``points[i]`` (degrees, one per
        motor) is due ``times[i]`` seconds after ``start_at`` (wall clock; None: now). Every
        point is checked first (``targets``: the limit rule); no point stops the trajectory.

        The trajectory leases its motors (``client`` names who sent it) until it ends, is
        stopped or replaced; with a ``writer``, motors another owner drives refuse it.

        Raises:
            UnknownMotorError: an unknown motor (nothing moved).
            ApiError: a point that is not one finite number per motor, times going back.
            ArgumentError: a ``start_at`` too far from now (``check_start_at``).
            CompliantMotorError: with ``refuse_compliant``, a compliant motor (nothing moved).
            MotorLeasedError: with a ``writer``, a motor another owner drives (nothing moved).
        """
        if not points:
            self.follower.stop()
            return None
        names = tuple(motors)
        if len(set(names)) != len(names):
            raise ApiError("invalid", "the trajectory names a motor twice")
        checked: list[tuple[float, ...]] = []
        for index, point in enumerate(points):
            if len(point) != len(names):
                raise ApiError(
                    "invalid", f"point {index} has {len(point)} positions for {len(names)} motors"
                )
            if index and times[index] < times[index - 1]:
                raise ApiError("invalid", f"point {index} goes back in time")
            goals = self.targets(dict(zip(names, point, strict=True)))
            checked.append(tuple(goals[n] for n in names))
        self._goals([self.motor(n) for n in names], refuse_compliant, writer)
        when = check_start_at(start_at)
        start = None if when is None or when <= time.time() else on_monotonic(when)
        waypoints = Waypoints(names, tuple(float(t) for t in times), tuple(checked), start)
        lease = Lease("trajectory", client=client, holder=writer)
        self.leases.take(lease, names, strict=writer is not None)
        followed = self.follower.follow(waypoints)
        lease.alive = lambda: self.follower.current is followed
        return followed

    def chain_goto(
        self,
        chain: RobotChain,
        position: Vector,
        orientation: Orientation,
        duration_s: float,
        *,
        linear: bool = False,
        client: str = "",
    ) -> tuple[dict[str, float], ChainMove]:
        """A v1 chain goto (a strict writer): the angles solved and the motion started.

        Its active motors go through the goal step (``_goals``, v1's rule: a compliant motor is
        refused), then it leases them until it ends (``chain_gotos``; ``client`` names who asked).

        Raises:
            KinematicsError: out of reach (nothing moved).
            MotorLeasedError: a motor another owner drives (nothing moved).
            CompliantMotorError: a compliant active motor (nothing moved).
        """
        angles = chain.solve(position, orientation)
        self._goals(chain.active_motors, True, chain_holder(chain, client))

        def begin() -> ChainMove:
            if linear:
                return chain.goto_linear(position, orientation, duration=duration_s)
            return chain.goto(position, orientation, duration=duration_s)

        return angles, self.chain_gotos.start(chain, client, begin)

    def stop_following(self) -> bool:
        """Stop the trajectory followed (the motors hold their goals); True when one was."""
        return self.follower.stop()

    def release_leases(self, reason: str) -> list[str]:
        """The robot-wide stop's part: end every teleoperation, the trajectory and the chains'
        straight moves, and free every lease (moves and primitives are stopped by the caller);
        the owners released."""
        owners = sorted({lease.label for lease in self.leases.owners().values()})
        self.teleop.close(reason)
        self.follower.stop()
        self.chain_gotos.stop_all()
        self.leases.release_all()
        return owners

    # -- lifetime ----------------------------------------------------------------------------

    def close(self) -> None:
        """Stop the recordings, playbacks, trajectory, chains' straight moves and
        teleoperations this server started; a dataset recording keeps its saved episodes."""
        self.recordings.close()
        self.teleop.close()
        self.follower.close()
        self.chain_gotos.stop_all()
        self.moves.close()
