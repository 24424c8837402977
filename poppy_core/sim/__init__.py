"""MuJoCo physics behind the virtual servos: models (MJCF), the plant and the simulation handle.

Every module of this room needs MuJoCo (the ``sim`` extra): importing the room checks it first.
"""

from poppy_core.extras import require

require("mujoco", extra="sim")
