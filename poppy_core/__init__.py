"""poppy_core: drive robots built from Robotis Dynamixel servos, real or emulated."""

import os

__version__ = "0.1.0"

# MuJoCo chooses its OpenGL backend once, when it is first imported, from MUJOCO_GL (glfw when
# unset, which needs a display). Without a display poppy renders offscreen with EGL; setting it
# here, before any room imports mujoco, makes every path (simulation, cameras, kinematics) agree.
if "MUJOCO_GL" not in os.environ and not os.environ.get("DISPLAY"):
    os.environ["MUJOCO_GL"] = "egl"
