"""Motion: trajectories (minimum jerk, constant speed); primitives and moves build on them."""

from poppy_core.motion.attached import (
    active_primitives,
    attach_primitive,
    attached_primitive,
    attached_primitives,
)
from poppy_core.motion.builtins import (
    BUILTINS,
    Cosinus,
    PositionWatcher,
    Sinus,
    Square,
    attach_builtins,
)
from poppy_core.motion.loop_primitive import LoopPrimitive
from poppy_core.motion.manager import FILTERS, PrimitiveManager, primitive_manager
from poppy_core.motion.move import Move
from poppy_core.motion.move_format import (
    FORMATS,
    MOVE_SUFFIX,
    PYPOT_SUFFIX,
    decode_any,
    decode_move,
    decode_pypot,
    encode_move,
    encode_pypot,
    read_move,
    write_move,
)
from poppy_core.motion.move_library import (
    MOVES_DIR_ENV,
    MoveEntry,
    check_name,
    delete_move,
    export_move,
    fallback_path,
    import_move,
    is_move_name,
    list_moves,
    load_move,
    move_path,
    moves_dir,
    save_move,
)
from poppy_core.motion.play_plan import PlayProgress
from poppy_core.motion.player import MovePlayer
from poppy_core.motion.primitive import Primitive
from poppy_core.motion.primitive_failure import PrimitiveFailure
from poppy_core.motion.recorder import MoveRecorder
from poppy_core.motion.sandbox import MockupMotor, MockupRobot
from poppy_core.motion.simple_posture import SimplePosture
from poppy_core.motion.teleop import (
    Follower,
    JointLink,
    JointMap,
    LocalFollower,
    Teleoperation,
    TeleopReport,
    TeleopStatus,
    teleoperate,
)
from poppy_core.trajectory import CONTROLS, MinimumJerk, dummy_speed

__all__ = [
    "BUILTINS",
    "CONTROLS",
    "FILTERS",
    "Cosinus",
    "LoopPrimitive",
    "MinimumJerk",
    "MockupMotor",
    "MockupRobot",
    "PositionWatcher",
    "Primitive",
    "PrimitiveFailure",
    "PrimitiveManager",
    "SimplePosture",
    "Sinus",
    "Square",
    "active_primitives",
    "attach_builtins",
    "attach_primitive",
    "attached_primitive",
    "attached_primitives",
    "dummy_speed",
    "primitive_manager",
]

# Moves: record, play, files and the library.
__all__ += [
    "FORMATS",
    "MOVES_DIR_ENV",
    "MOVE_SUFFIX",
    "PYPOT_SUFFIX",
    "Move",
    "MoveEntry",
    "MovePlayer",
    "MoveRecorder",
    "PlayProgress",
    "check_name",
    "decode_any",
    "decode_move",
    "decode_pypot",
    "delete_move",
    "encode_move",
    "encode_pypot",
    "export_move",
    "fallback_path",
    "import_move",
    "is_move_name",
    "list_moves",
    "load_move",
    "move_path",
    "moves_dir",
    "read_move",
    "save_move",
    "write_move",
]

# Teleoperation: a follower copies a leader moved by hand.
__all__ += [
    "Follower",
    "JointLink",
    "JointMap",
    "LocalFollower",
    "TeleopReport",
    "TeleopStatus",
    "Teleoperation",
    "teleoperate",
]
