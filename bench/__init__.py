"""Benchmarks comparing poppy with pypot and dynamixel-sdk; run with ``python -m bench``."""
