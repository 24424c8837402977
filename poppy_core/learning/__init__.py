"""Learning: Gymnasium environments on the MuJoCo simulation (``poppy_core.learning.envs``)."""
