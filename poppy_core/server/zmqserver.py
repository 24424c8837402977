"""pypot's ZMQ request/reply server: ``{"robot": {method: {arguments}}}`` in, a JSON value out.

The protocol is pypot's ``ZMQRobotServer`` (REP socket, one JSON request, one JSON reply; the
method names of its ``RESTRobot``): ``get_motors_list``, ``get_register_value``,
``set_register_value``, ``set_goto_position_for_motor``, primitive start/stop/pause/resume and
properties, move recording and playing. A reply is the method's value (``{}`` for none); a bad
request gets ``{"error": "<one line>"}`` and the server carries on. Loopback by default.
"""

from __future__ import annotations

import json
import logging
import threading
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

from poppy_core import checks
from poppy_core.errors import PoppyError
from poppy_core.extras import require
from poppy_core.schedule import Worker
from poppy_core.server.errors import ApiError, ListenError, refusal_kind
from poppy_core.server.service import RobotService
from poppy_core.trajectory import goto_duration

if TYPE_CHECKING:
    from poppy_core.robot import Robot

logger = logging.getLogger(__name__)

DEFAULT_PORT = 6768
MAX_MESSAGE_BYTES = 1024 * 1024
POLL_MS = 100
# The documentation's ZMQ example reads 'present_pos' and writes 'goal_pos'.
REGISTER_SPELLINGS = {"present_pos": "present_position", "goal_pos": "goal_position"}


def _json_argument(value: Any) -> Any:
    """pypot sends ``value`` and ``args`` JSON-encoded in a string; plain values are taken too."""
    if isinstance(value, str):
        try:
            return json.loads(value)
        except ValueError:
            return value  # a plain string (a colour name, 'safe'...)
    return value


class ZmqRequests:
    """pypot's ``RESTRobot`` methods over a ``RobotService``: ``handle(request) -> reply``."""

    def __init__(self, service: RobotService) -> None:
        self.service = service
        self.methods: dict[str, Callable[..., Any]] = {
            "get_motors_list": self.get_motors_list,
            "get_motor_registers_list": self.get_registers_list,
            "get_registers_list": self.get_registers_list,
            "get_motor_register_value": self.get_register_value,
            "get_register_value": self.get_register_value,
            "set_motor_register_value": self.set_register_value,
            "set_register_value": self.set_register_value,
            "get_motors_alias": lambda: list(service.groups()),
            "set_goto_position_for_motor": self.set_goto_position_for_motor,
            "set_goto_positions_for_motors": self.set_goto_positions_for_motors,
            "get_primitives_list": lambda: list(service.primitives()),
            "get_running_primitives_list": service.pypot_running_primitives,
            "start_primitive": lambda primitive: self._control(primitive, "start"),
            "stop_primitive": lambda primitive: self._control(primitive, "stop"),
            "pause_primitive": lambda primitive: self._control(primitive, "pause"),
            "resume_primitive": lambda primitive: self._control(primitive, "resume"),
            "get_primitive_properties_list": lambda primitive: service.property_names(primitive),
            "get_primitive_property": lambda primitive, property: service.get_property(
                primitive, property
            ),
            "set_primitive_property": lambda primitive, property, value: self._none(
                service.set_property(primitive, property, value)
            ),
            "get_primitive_methods_list": lambda primitive: service.method_names(primitive),
            "call_primitive_method": self.call_primitive_method,
            "start_move_recorder": self.start_move_recorder,
            "stop_move_recorder": lambda move_name: self._none(service.moves.save(move_name)),
            "start_move_player": self.start_move_player,
            "get_available_record_list": service.moves.names,
            "remove_move_record": service.moves.delete,
        }

    def handle(self, request: Any) -> Any:
        """The reply to one decoded request; ``{"error": ...}`` when it is refused."""
        try:
            name, arguments = self._parse(request)
            method = self.methods.get(name)
            if method is None:
                raise ApiError(
                    "not_found", f"no method {name!r} (methods: {', '.join(sorted(self.methods))})"
                )
            for key in ("value", "args"):
                if key in arguments:
                    arguments[key] = _json_argument(arguments[key])
            result = method(**arguments)
        except TypeError as exc:  # missing or unexpected arguments
            return {"error": f"bad arguments: {exc}", "kind": "invalid"}
        except (ApiError, PoppyError, ValueError, KeyError, ArithmeticError) as exc:
            return {"error": _one_line(exc), "kind": refusal_kind(exc)}
        return {} if result is None else result

    @staticmethod
    def _parse(request: Any) -> tuple[str, dict[str, Any]]:
        if not isinstance(request, Mapping) or not isinstance(request.get("robot"), Mapping):
            raise ApiError("invalid", 'expected {"robot": {"<method>": {<arguments>}}}')
        calls = request["robot"]
        if len(calls) != 1:
            raise ApiError("invalid", "one method per request")
        name, arguments = next(iter(calls.items()))
        if arguments is None:
            arguments = {}
        if not isinstance(arguments, Mapping):
            raise ApiError("invalid", f"{name}: the arguments must be an object")
        return str(name), {str(k): v for k, v in arguments.items()}

    @staticmethod
    def _none(_: Any) -> None:
        return None

    def get_motors_list(self, alias: str = "motors") -> list[str]:
        return self.service.group(alias)

    def get_registers_list(self, motor: str) -> list[str]:
        return list(self.service.motor(motor).registers)

    def get_register_value(self, motor: str, register: str) -> Any:
        return self.service.read(motor, REGISTER_SPELLINGS.get(register, register))

    def set_register_value(self, motor: str, register: str, value: Any) -> None:
        self.service.write(motor, REGISTER_SPELLINGS.get(register, register), value)

    def set_goto_position_for_motor(
        self, motor: str, position: Any, duration: Any, wait: Any = False
    ) -> None:
        handle = self.service.goto({motor: position}, duration)
        if wait:
            handle.wait(goto_duration(duration) + 5.0)

    def set_goto_positions_for_motors(
        self,
        motors: list[str],
        positions: list[Any],
        duration: Any,
        control: str | None = None,
        wait: Any = False,
    ) -> None:
        if (
            not isinstance(motors, list)
            or not isinstance(positions, list)
            or len(motors) != len(positions)
        ):
            raise ApiError("invalid", "motors and positions must be lists of the same length")
        handle = self.service.goto(
            dict(zip(motors, positions, strict=True)), duration, control or "minjerk"
        )
        if wait:
            handle.wait(goto_duration(duration) + 5.0)

    def _control(self, primitive: str, action: str) -> None:
        self.service.control_primitive(primitive, action)

    def call_primitive_method(
        self, primitive: str, method: str, kwargs: Mapping[str, Any] | None = None
    ) -> Any:
        if kwargs is not None and not isinstance(kwargs, Mapping):
            raise ApiError("invalid", "kwargs must be an object")
        return self.service.call_method(primitive, method, (), kwargs)

    def start_move_recorder(self, move_name: str, motors_name: list[str] | None = None) -> None:
        self.service.moves.record(move_name, motors_name)

    def start_move_player(
        self, move_name: str, speed: float = 1.0, backwards: bool = False
    ) -> float:
        player = self.service.moves.play(
            move_name, checks.number(speed, "speed"), bool(backwards), client="ZMQ"
        )
        return player.duration_s


def _one_line(exc: BaseException) -> str:
    text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    return text if not isinstance(exc, KeyError) else f"missing {text}"


class ZmqRobotServer:
    """pypot's ZMQ server over ``robot``, serving in a thread.

    Args:
        robot: the robot (the caller keeps and closes it).
        host: the address to bind (loopback by default).
        port: the port (pypot's documentation uses 6768); 0 picks a free one.
        service: the robot service shared with the other servers of the robot
            (``poppy_core.assembly.serve``, which closes it); by default its own.

    Raises:
        ListenError: the address or port cannot be used.
    """

    def __init__(
        self,
        robot: Robot,
        host: str = "127.0.0.1",
        port: int = DEFAULT_PORT,
        *,
        service: RobotService | None = None,
    ) -> None:
        require("zmq", extra="zmq", feature="pypot's ZMQ server")
        import zmq

        self.host = host
        self._owns_service = service is None
        self.service = service or RobotService(robot)
        self.requests = ZmqRequests(self.service)
        self._context = zmq.Context()
        self._socket = self._context.socket(zmq.REP)
        self._socket.setsockopt(zmq.MAXMSGSIZE, MAX_MESSAGE_BYTES)
        self._socket.setsockopt(zmq.LINGER, 0)
        address = f"[{host}]" if ":" in host else host
        try:
            if port == 0:
                self.port = self._socket.bind_to_random_port(f"tcp://{address}")
            else:
                self._socket.bind(f"tcp://{address}:{port}")
                self.port = port
        except zmq.ZMQError as exc:
            self._socket.close()
            self._context.term()
            raise ListenError(
                f"cannot listen on {host}:{port}: {exc}; choose another port "
                "(--zmq-port) or stop the program using it"
            ) from None
        self._stop = threading.Event()  # stopped for good: a stopped server does not start
        self._released = False
        self._release_lock = threading.Lock()
        self._worker = Worker("zmq server", self._serve, on_exit=self._release)
        self.requests_served = 0

    @property
    def url(self) -> str:
        """``tcp://host:port``."""
        return f"tcp://{self.host}:{self.port}"

    @property
    def running(self) -> bool:
        """True while the server thread runs."""
        return self._worker.running

    def start(self) -> ZmqRobotServer:
        """Serve in a thread (again: nothing)."""
        if not self._worker.running and not self._stop.is_set():
            self._worker.start()
        return self

    def run(self, timeout_s: float | None = None) -> None:
        """Serve and block until ``stop()`` (pypot's ``server.run()``); when it already serves in
        the background (``use_zmq=True`` started it), return at once, as pypot did."""
        if self._worker.running:
            return
        self.start()
        self._stop.wait(timeout_s)

    def _serve(self, stopping: threading.Event) -> None:
        """Answer requests until stopped (``_release`` closes the socket after, whatever the
        way the loop ended)."""
        import zmq

        socket = self._socket
        socket.setsockopt(zmq.RCVTIMEO, POLL_MS)  # wake up to see stop() without a poll per request
        while not stopping.is_set():
            try:
                raw = socket.recv()
            except zmq.Again:
                continue
            except zmq.ZMQError as exc:
                if stopping.is_set():
                    break
                logger.warning("zmq server: %s", exc)
                continue
            reply = self.reply_to(raw)
            try:
                socket.send(reply)
            except zmq.ZMQError as exc:
                logger.warning("zmq server: reply not sent: %s", exc)
            self.requests_served += 1

    def _release(self) -> None:
        with self._release_lock:
            if self._released:
                return
            self._released = True
        self._socket.close()
        self._context.term()

    def reply_to(self, raw: bytes) -> bytes:
        """The encoded reply to one encoded request (never raises)."""
        try:
            request = json.loads(raw)
        except (ValueError, RecursionError) as exc:
            answer: Any = {"error": f"the request is not JSON: {_one_line(exc)}"}
        else:
            try:
                answer = self.requests.handle(request)
            except Exception as exc:  # a server must answer, whatever failed
                logger.exception("zmq request %r failed", raw[:200])
                answer = {"error": f"internal error: {_one_line(exc)}"}
        try:
            return json.dumps(answer, allow_nan=False).encode()
        except (TypeError, ValueError) as exc:
            return json.dumps({"error": f"the reply is not JSON: {exc}"}).encode()

    def stop(self) -> None:
        """Stop serving and release the port (again: nothing)."""
        if self._stop.is_set():
            return
        self._stop.set()
        if self._worker.running:
            self._worker.close(5.0)  # the thread releases the port as it ends
        else:
            self._release()
        if self._owns_service:
            self.service.close()


ZMQRobotServer = ZmqRobotServer
"""pypot's name: ``server = ZMQRobotServer(robot, "127.0.0.1", 6768); server.run()``."""


def start_zmq_server(
    robot: Robot, host: str = "127.0.0.1", port: int = DEFAULT_PORT, *, start: bool = True
) -> ZmqRobotServer:
    """A ``ZmqRobotServer`` over ``robot``, serving unless ``start`` is False.

    Raises:
        ListenError: the address or port cannot be used.
    """
    server = ZmqRobotServer(robot, host, port)
    return server.start() if start else server
