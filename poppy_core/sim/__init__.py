"""MuJoCo physics behind the virtual servos: models (MJCF), the plant and the simulation handle."""
