"""The optional dependencies (pyproject's extras): import one, or say in one line which extra
to install.

The core (``pip install poppy``) scans buses, drives motors and robots, plays moves and emulates.
Each heavier room is an extra; the first use of a missing one raises ``MissingExtraError``::

    require("mujoco", extra="sim", feature="the MuJoCo simulation")
    import mujoco  # now loaded (or the line above raised)
"""

from __future__ import annotations

import importlib

from poppy_core.errors import MissingExtraError

EXTRAS: dict[str, str] = {
    "sim": "the MuJoCo simulation",
    "vision": "cameras and marker detection (OpenCV)",
    "faces": "face detection (scikit-image)",
    "server": "the web servers (REST, WebSocket, Snap!, the web page)",
    "zmq": "pypot's ZMQ server",
    "fleet": "Zenoh fleets (serve --zenoh, poppy fleet, zenoh: remote robots)",
    "ros2": "ROS 2 over rmw_zenoh (serve --ros2)",
    "foxglove": "Foxglove without ROS (serve --foxglove, record --mcap, dataset view --mcap)",
    "tui": "the terminal app",
    "plot": "plots (matplotlib)",
    "notebook": "Jupyter notebooks (`poppy notebook`)",
    "appliance": "the robot's name on the network (mDNS/DNS-SD with zeroconf)",
    "dataset": "LeRobot datasets (pyarrow, PyAV)",
    "rerun": "Rerun recordings of a dataset's episodes (dataset view --rerun)",
    "gym": "Gymnasium environments on the simulation (gymnasium, MuJoCo)",
}
"""Extra -> what it brings (pyproject.toml's ``[project.optional-dependencies]``)."""


def install_hint(extra: str) -> str:
    """The command that installs ``extra``."""
    return f"pip install 'poppy[{extra}]'"


def require(*modules: str, extra: str, feature: str | None = None) -> None:
    """Import ``modules`` (so a plain ``import`` after this call is free), or raise.

    Raises:
        MissingExtraError: a module is not installed (or cannot be imported): the message names
            the feature, the extra and the command that installs it, in one line.
    """
    what = feature or EXTRAS.get(extra, extra)
    for module in modules:
        try:
            importlib.import_module(module)
        except ImportError as exc:
            top = module.partition(".")[0]
            absent = isinstance(exc, ModuleNotFoundError)
            if absent and (exc.name or top).partition(".")[0] == top:
                message = f"{top} is not installed (used by {what}): {install_hint(extra)}"
            else:
                message = f"{top} cannot be imported ({exc}; used by {what}): {install_hint(extra)}"
            raise MissingExtraError(message, extra=extra, module=module) from None
