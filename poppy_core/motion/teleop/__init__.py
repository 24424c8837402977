"""Teleoperation: a follower robot copies a leader moved by hand (``teleoperate``).

``session``: the loop (``Teleoperation``, ``teleoperate``); ``follower``: the follower interface and
the local follower; ``goal_stream``: the ramp, hold and resume of streamed goals (shared with the
server's teleop channel); ``joint_map``: which leader joint drives which follower joint;
``recording``: the follower's positions saved as a move; ``stats``: what a teleoperation reports;
``leader``: what it needs of the robot moved by hand (``Leader``, a local robot or a served one).
"""

from poppy_core.motion.teleop.follower import Follower, LocalFollower
from poppy_core.motion.teleop.goal_stream import GoalStream, GoalStreamChange
from poppy_core.motion.teleop.joint_map import JointLink, JointMap
from poppy_core.motion.teleop.leader import Leader, LeaderMotor
from poppy_core.motion.teleop.recording import TrajectoryRecorder
from poppy_core.motion.teleop.session import Teleoperation, teleoperate
from poppy_core.motion.teleop.stats import TeleopReport, TeleopStatus

__all__ = [
    "Follower",
    "GoalStream",
    "GoalStreamChange",
    "JointLink",
    "JointMap",
    "Leader",
    "LeaderMotor",
    "LocalFollower",
    "TeleopReport",
    "TeleopStatus",
    "Teleoperation",
    "TrajectoryRecorder",
    "teleoperate",
]
