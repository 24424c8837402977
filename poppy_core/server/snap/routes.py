"""The Snap! text routes: pypot's paths and what each does (``SnapRobot``'s methods).

Order matters where two templates can match one path: the MoveRecorder/MovePlayer routes come
before the generic primitive routes (a move may be called ``get``), ``/motors/alias`` before
``/motors/{alias}``.
"""

from __future__ import annotations

from poppy_core.server.snap.routing import Handler, TextRoute
from poppy_core.server.snap.snap_robot import SnapRobot


def _control(action: str) -> Handler:
    def handler(snap: SnapRobot, params: dict[str, str]) -> str:
        return snap.control(params["primitive"], action)

    return handler


def _routes() -> list[TextRoute]:
    r = TextRoute
    return [
        # motors
        r("/motors/alias", lambda s, p: s.aliases()),
        r("/motors/get/positions", lambda s, p: s.positions()),
        r("/motors/set/registers/{settings}", lambda s, p: s.write_many(p["settings"])),
        r("/motors/set/goto/{settings}", lambda s, p: s.goto_many(p["settings"])),
        r("/motors/set/positions/{positions}", lambda s, p: s.set_positions(p["positions"])),
        r("/motors/{motors}/get/{register}", lambda s, p: s.read_many(p["motors"], p["register"])),
        r("/motors/{alias}", lambda s, p: s.motors_of(p["alias"])),
        r("/motor/{motor}/get/{register}", lambda s, p: s.read(p["motor"], p["register"])),
        r(
            "/motor/{motor}/set/{register}/{value}",
            lambda s, p: s.write(p["motor"], p["register"], p["value"]),
        ),
        r(
            "/motor/{motor}/goto/{position}/{duration}",
            lambda s, p: s.goto(p["motor"], p["position"], p["duration"]),
        ),
        # moves (before the generic primitive routes: a move may be called "get")
        r("/primitive/MoveRecorder", lambda s, p: s.moves()),
        r("/primitive/MovePlayer", lambda s, p: s.moves()),
        r("/primitive/MoveRecorder/{move}/start", lambda s, p: s.record(p["move"])),
        r(
            "/primitive/MoveRecorder/{move}/start/{motors}",
            lambda s, p: s.record(p["move"], p["motors"]),
        ),
        r(
            "/primitive/MoveRecorder/{move}/attach/{motors}",
            lambda s, p: s.attach(p["move"], p["motors"]),
        ),
        r("/primitive/MoveRecorder/{move}/get_motors", lambda s, p: s.recorded_motors(p["move"])),
        r("/primitive/MoveRecorder/{move}/stop", lambda s, p: s.save(p["move"]), blocking=True),
        r("/primitive/MoveRecorder/{move}/remove", lambda s, p: s.remove(p["move"]), blocking=True),
        r("/primitive/MovePlayer/{move}/start", lambda s, p: s.play(p["move"]), blocking=True),
        r(
            "/primitive/MovePlayer/{move}/start/{speed}",
            lambda s, p: s.play(p["move"], p["speed"]),
            blocking=True,
        ),
        r(
            "/primitive/MovePlayer/{move}/start/{speed}/backwards",
            lambda s, p: s.play(p["move"], p["speed"], backwards=True),
            blocking=True,
        ),
        r("/primitive/MovePlayer/{move}/stop", lambda s, p: s.stop_playing(p["move"])),
        r(
            "/moves/concurrently/{moves}/{speed}",
            lambda s, p: s.play_together(p["moves"], p["speed"]),
            blocking=True,
        ),
        r(
            "/moves/sequentially/{moves}/{speed}",
            lambda s, p: s.play_in_sequence(p["moves"], p["speed"]),
            blocking=True,
        ),
        # primitives
        r("/primitives", lambda s, p: s.primitives()),
        r("/primitives/running", lambda s, p: s.running()),
        *(
            r(f"/primitive/{{primitive}}/{action}", _control(action), blocking=True)
            for action in ("start", "stop", "pause", "resume")
        ),
        r("/primitive/{primitive}/properties", lambda s, p: s.properties(p["primitive"])),
        r("/primitive/{primitive}/methodes", lambda s, p: s.methods(p["primitive"])),
        r(
            "/primitive/{primitive}/get/{prop}",
            lambda s, p: s.get_property(p["primitive"], p["prop"]),
        ),
        r(
            "/primitive/{primitive}/set/{prop}/{value}",
            lambda s, p: s.set_property(p["primitive"], p["prop"], p["value"]),
        ),
        r(
            "/primitive/{primitive}/call/{method}",
            lambda s, p: s.call(p["primitive"], p["method"]),
            blocking=True,
        ),
        r(
            "/primitive/{primitive}/call/{method}/{args}",
            lambda s, p: s.call(p["primitive"], p["method"], p["args"]),
            blocking=True,
        ),
        # the connection test, sensors, simulation, kinematics, address
        r("/connected", lambda s, p: s.connected()),
        r("/motor/{motor}/index", lambda s, p: s.motor_index(p["motor"])),
        r("/detect/{marker}", lambda s, p: s.detect(p["marker"]), blocking=True),
        r("/reset-simulation", lambda s, p: s.reset_simulation(), blocking=True),
        r("/ik/{chain}/endeffector", lambda s, p: s.tip(p["chain"])),
        r(
            "/ik/{chain}/goto/{x}/{y}/{z}/{duration}",
            lambda s, p: s.ik_goto(p["chain"], (p["x"], p["y"], p["z"]), p["duration"]),
            blocking=True,
        ),
    ]


ROUTES = _routes()
"""The text routes (the documents, the frame and the address are Starlette routes of the app)."""
