"""Release the motors and take them back: the page's "kill all access to the motors", the REST
routes ``/api/v1/motors/release`` and ``/take``, and `poppy service release`/`take`.

Releasing stops what moves the robot (primitives, moves playing), makes every motor compliant
and closes the ports (``Robot.release_motors``), so another program can open them; taking them
back reopens the ports. The emergency Stop (``/api/v1/web/stop``) is another thing: it keeps
the ports.
"""

from __future__ import annotations

import logging
from typing import Any

from poppy_core.robot.build_steps import no_motors_message
from poppy_core.server.service import RobotService

logger = logging.getLogger(__name__)


def halt_activity(service: RobotService) -> tuple[list[str], list[str]]:
    """Stop every primitive running, every move playing, every teleoperation, the trajectory
    and a dataset recording (as its Esc: the episode under way is saved), and free every motor's
    lease (``motion/leases.py``); the primitives' and the moves' names."""
    service.recordings.stop()  # first: its move or primitive is not started again
    stopped = service.running_primitives()
    for name in stopped:
        service.primitive(name).halt(wait=True)
    moves = service.moves.stop_all()  # a playback being started too
    service.release_leases("the robot was stopped")
    return stopped, moves


def release_motors(service: RobotService) -> dict[str, Any]:
    """Stop primitives and moves, make the motors compliant, close the ports; what was done."""
    primitives, moves = halt_activity(service)
    ports = service.robot.release_motors()
    logger.warning(
        "motors released (primitives stopped: %s; moves stopped: %s): %s free for another "
        "program until they are taken back",
        ", ".join(primitives) or "none",
        ", ".join(moves) or "none",
        ", ".join(ports) or "no port",
    )
    return {**access_state(service), "primitives": primitives, "moves": moves}


def take_motors(service: RobotService) -> dict[str, Any]:
    """Reopen the ports and find the motors again (they stay compliant).

    Raises:
        PortError: a port is held by another program (the motors stay released).
    """
    service.robot.take_motors()
    return access_state(service)


def access_state(service: RobotService) -> dict[str, Any]:
    """Released or not, the ports, and the buses where no motor answers (with what to check:
    the robot waits for them, as when it starts before its power is on)."""
    robot = service.robot
    config = robot.config
    waiting = []
    if not robot.released:
        for controller, health in robot.health().items():
            motors = set(config.motors_of_controller(controller)) if config else set()
            if not health.connected or (motors and motors <= set(health.offline)):
                waiting.append({"port": health.port, "message": no_motors_message(health.port)})
    return {"released": robot.released, "ports": robot.ports, "no_motors": waiting}
