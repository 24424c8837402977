"""poppy_core: drive robots built from Robotis Dynamixel servos, real or emulated."""

__version__ = "0.1.0"
