"""The Poppy documentation's Python examples, as a pypot user runs them on poppy.

Each is the documentation's code (``../shared/reference``, line given) with its import line
changed to poppy's and Python 2 prints and typographic quotes written as Python 3. ``run``
executes one with the documentation's durations shortened: ``time.sleep`` and ``time.time``
and a primitive's ``self.elapsed_time`` are the only names it touches, and it scales them all, so
an example's timing logic is unchanged.
"""

from __future__ import annotations

import textwrap
import time
from typing import Any

TIME_SCALE = 0.2
"""Real seconds per documentation second."""


def _sleep(seconds: float) -> None:
    time.sleep(seconds * TIME_SCALE)


def _clock() -> float:
    return time.monotonic() / TIME_SCALE


def _elapsed(primitive: Any) -> float:
    return float(primitive.elapsed_time) / TIME_SCALE


def run(code: str, **names: Any) -> dict[str, Any]:
    """Run an example with ``names`` defined (``poppy``...); its namespace afterwards."""
    source = textwrap.dedent(code)
    source = source.replace("time.sleep(", "_doc_sleep(").replace("time.time()", "_doc_clock()")
    source = source.replace("self.elapsed_time", "_doc_elapsed(self)")
    namespace: dict[str, Any] = {
        "_doc_sleep": _sleep,
        "_doc_clock": _clock,
        "_doc_elapsed": _elapsed,
        **names,
    }
    exec(compile(source, "<documentation example>", "exec"), namespace)
    return namespace


# -- constructors (1.4 "Programming with Python"; the creature libraries) -----------------------

CREATE_ERGO_JR = """
from poppy_core.pypot import PoppyErgoJr
poppy = PoppyErgoJr(simulator=SIMULATOR)
"""  # line 462, with the simulator the test runs on

FROM_JSON = """
import poppy_core.pypot
poppy = poppy_core.pypot.from_json('my_config.json', use_dummy_io=True)
"""  # line 476 (`use_dummy_io`: virtual servos, no hardware here)

# -- motors and groups (line 484-591) -----------------------------------------------------------

LIST_MOTORS = """
print(poppy.motors)
for m in poppy.motors:
    print('motor {} in position {}'.format(m.name, m.present_position))
"""  # lines 484, 520

GROUPS = """
for group in poppy.alias:
    print("motor group ", group)

# assuming "head" is one of the motor groups (use "top" for a ergo_jr)
for m in poppy.head:
    print('motor {} in position {}'.format(m.name, m.present_position))
"""  # line 527

COMPLIANCE = """
# set the whole robot compliant
poppy.compliant = True

# set the whole motor group non-compliant
poppy.head.compliant = False

# set thone motor non-compliant
poppy.l_shoulder_x.compliant = False
"""  # line 546

GOAL_POSITION = """
import time

poppy.head_z.goal_position = 20.
poppy.head_y.goal_position = 10.

time.sleep(2) # wait 2 seconds

poppy.head_y.goal_position = -10.
"""  # line 561

MOVING_SPEED = """
import time

poppy.head_y.moving_speed = 150.
poppy.head_y.goal_position = 10.

time.sleep(2) # wait 2 seconds
poppy.head_y.moving_speed = 50.
poppy.head_y.goal_position = -10.
"""  # line 576

GOTO = """
poppy.head_y.goto_position(10.,1.,wait=True)
poppy.head_y.goto_position(-10.,2.,wait=False)
"""  # line 591

# -- the robot API (3.x "Robot", lines 3057-3253; `robot` is the documentation's name) ----------

ROBOT_GOTO = """
robot.goto_position({'head_z':0., 'head_y':20}, 3)
"""  # line 3095

ROBOT_GOTO_DUMMY = """
robot.goto_position({'head_z':0., 'head_y':20}, 3, control='dummy', wait=True)
"""  # line 3107

MOTOR_INFO = """
for m in robot.motors:
    print("motor ", m.name, "(", m.model, "), id: ", m.id)
    print('temperature: ', m.temperature)
    print("load: ", m.load)
"""  # line 3160

SAFE_COMPLIANCE = """
print(robot.head_z.angle_limit)
robot.head_z.compliant_behavior('safe')
robot.head_z.compliant = True
#now try moving the head with your hands beyond the angle limits
"""  # line 3177

MAX_TORQUE = """
robot.head_z.max_torque = 20
"""  # line 3186

ALL_TO_ZERO = """
for m in robot.motors:
    m.compliant = False
    m.goal_position = 0

time.sleep(2)

for m in robot.motors:
    print("position: ", m.present_position, "(limits: ", m.angle_limit, ")")
"""  # line 3196

GOAL_SPEED = """
goal = 20

t_init = time.time()

while time.time() - t_init < 20:

    if abs(robot.head_y.present_position) > abs(goal):
        goal = -goal

    speed = 0.1*(goal - robot.head_y.present_position)
    robot.head_y.goal_speed = speed

    time.sleep(0.1)
"""  # line 3213

MOTOR_GOTO = """
robot.head_z.goto_position(20, 3)
"""  # line 3239

MOTOR_GOTO_DUMMY = """
robot.head_z.goto_position(20, 3, control='dummy', wait=True)
"""  # line 3253

# -- primitives (line 3289) ---------------------------------------------------------------------

SINUS = """
from poppy_core.motion import Sinus

sinus_prim_z = Sinus(poppy, 50, "head_z", amp=30, freq=0.5, offset=0, phase=0)

#set phase to 90° to have the y sinus 1/4 of phase late compared to the z sinus
sinus_prim_y = Sinus(poppy, 50, "head_y", amp=20, freq=1, offset=0, phase=90)

print("start moving")
sinus_prim_z.start()
sinus_prim_y.start()

time.sleep(20)

print("pause move")
sinus_prim_z.pause()
sinus_prim_y.pause()

time.sleep(5)

print("restart move")
sinus_prim_z.resume()
sinus_prim_y.resume()

time.sleep(20)

print("stop moving")
sinus_prim_z.stop()
sinus_prim_y.stop()
"""

# -- record and replay (lines 2677, 2707) -------------------------------------------------------

RECORD = """
from poppy_core.motion import Move, MoveRecorder, MovePlayer

record_frequency = 20.0 # This means that a new position will be recorded 50 times per second
recorded_motors = poppy.motors # We will record the position of all motors

#disable torque for all motors
for m in recorded_motors:
    m.compliant = True

#create the recorder primitive
recorder = MoveRecorder(poppy, record_frequency, recorded_motors)

print("start recording")
recorder.start()

time.sleep(20)

print("stop recording")
recorder.stop()

#save the recorded move in a file
with open('mymove.json', 'w') as f:
    recorder.move.save(f)
"""

REPLAY = """
#read the file containing the move
with open('mymove.json') as f:
    loaded_move = Move.load(f)

#create the primitive
player = MovePlayer(poppy, loaded_move)

#enable torque for all motors
for m in poppy.motors:
    m.compliant = False

print("starting")
player.start()
player.wait_to_stop()
print("finished")

#disable torque for all motors
for m in poppy.motors:
    m.compliant = True

time.sleep(0.1)
"""

# -- the Humanoid's setup (line 2138), on a built robot -----------------------------------------

HUMANOID_SETUP = """
from functools import partial
import numpy

robot._primitive_manager._filter = partial(numpy.sum, axis=0)

for m in robot.motors:
    m.goto_behavior = 'minjerk'

for m in robot.torso:
    m.compliant_behavior = 'safe'
"""

# -- pypot.robot.from_config with the Ergo's config (line 2636) ---------------------------------

FROM_CONFIG = """
import poppy_core.pypot

ergo_robot = poppy_core.pypot.from_config(my_config, sim=True)
print(ergo_robot.m2.present_position) #get register present_position of motor m2

ergo_robot.m6.compliant = False          #enable torque of the m6 motor
ergo_robot.m6.goal_position = 20         #set goal position of motor m6 to 20 degree

time.sleep(2)                           #wait for the robot to move
"""  # `sim=True`: the documentation's robot is real; the module path is poppy's

# -- the creature libraries (lines 1845, 1945) and their behaviours ------------------------------

CREATE_HUMANOID = """
from poppy_core.pypot import PoppyHumanoid

poppy = PoppyHumanoid(simulator=SIMULATOR)

print(poppy.motors)
"""  # line 1845, with the simulator the test runs on

CREATE_TORSO = """
from poppy_core.pypot import PoppyTorso
poppy = PoppyTorso(simulator=SIMULATOR)
print(poppy.motors)
"""  # line 1945

SIT_POSITION = """
poppy.sit_position.start()
"""  # line 1871 ("so you can directly use `poppy.sit_position.start()`")

LIMIT_TORQUE = """
poppy.limit_torque.start()
"""  # line 1969 ("so you can directly use `poppy.limit_torque.start()`")

# -- the simulated Humanoid (2.2 "Using V-REP", lines 850-867) -----------------------------------

SIMULATED_HEAD = """
# print all motors
print(poppy.motors)
#ask a new position for the head
poppy.head_z.goal_position = -10

#wait a bit
import time
time.sleep(2.)

#print head_z position
print(poppy.head_z.present_position)
"""  # line 850

RESET_SIMULATION = """
poppy.reset_simulation()
"""  # line 867

OBJECT_POSITION = """
print(poppy.get_object_position('l_forearm_visual'))
print(poppy.get_object_position('l_forearm_visual', 'head_visual'))
"""  # lines 893, 899 (V-REP's names; a bare expression in the documentation, printed here)

# -- the robot object (lines 3058-3078) ---------------------------------------------------------

ROBOT_OVERVIEW = """
for m in robot.motors:
    print(m.name)

print(robot.head_z.present_position)

for m in robot.head:
    print(m.name)

robot.compliant = True
"""  # lines 3058, 3065, 3071, 3078

# -- sensors (lines 607-642) --------------------------------------------------------------------

SENSORS = """
print(poppy.sensors)
print([sensor.name for sensor in poppy.sensors])
print (poppy.camera)
print(poppy.camera.registers)
print (poppy.camera.resolution)
"""  # lines 607, 615, 622, 634, 641

# -- writing your own primitive (lines 3372-3452) -----------------------------------------------

DANCE_PRIMITIVE = """
import time

import poppy_core.motion
class DancePrimitive(poppy_core.motion.Primitive):

    def __init__(self, robot, amp=30, freq=0.5):
        self.robot = robot
        self.amp = amp
        self.freq = freq
        poppy_core.motion.Primitive.__init__(self, robot)

    def run(self):
        amp = self.amp
        freq = self.freq
        # self.elapsed_time gives you the time (in s) since the primitive has been running
        while self.elapsed_time < 30:
            x = amp * numpy.sin(2 * numpy.pi * freq * self.elapsed_time)

            self.robot.base_pan.goal_position = x
            self.robot.head_pan.goal_position = -x

            time.sleep(0.02)
"""  # line 3372; base_pan, head_pan: the old Poppy Ergo's (see ``ergo_motor_names``)

DANCE_START = """
dance = DancePrimitive(ergo_robot, amp=60, freq=0.6)
dance.start()
"""  # line 3399, after its placeholder `ergo_robot = pypot.robot.from_config(...)`

LOOP_DANCE_PRIMITIVE = """
class LoopDancePrimitive(poppy_core.motion.LoopPrimitive):
    def __init__(self, robot, refresh_freq, amp=30, freq=0.5):
        self.robot = robot
        self.amp = amp
        self.freq = freq
        LoopPrimitive.__init__(self, robot, refresh_freq)

    # The update function is automatically called at the frequency given on the constructor
    def update(self):
        amp = self.amp
        freq = self.freq
        x = amp * numpy.sin(2 * numpy.pi * freq * self.elapsed_time)

        self.robot.base_pan.goal_position = x
        self.robot.head_pan.goal_position = -x
"""  # line 3410

LOOP_DANCE_START = """
dance = LoopDancePrimitive(ergo_robot, 50, amp = 40, freq = 0.3)
# The robot will dance until you call dance.stop()
dance.start()
"""  # line 3428

ATTACH_DANCE = """
ergo_robot.attach_primitive(DancePrimitive(ergo_robot), 'dance')
ergo_robot.dance.start()
"""  # line 3440

SELECTOR_PRIMITIVE = """
class SelectorPrimitive(poppy_core.motion.Primitive):
    def run(self):
        if song == 'my_favorite_song_to_dance' and not self.robot.dance.is_alive():
            self.robot.dance.start()
"""  # line 3449

# The old Poppy Ergo's motors, named in the primitive examples -> the Ergo Jr's that turn about
# the same vertical axes at rest: the base (m1) and the head's pan (m4).
ERGO_MOTOR_NAMES = {"base_pan": "m1", "head_pan": "m4"}


def ergo_motor_names(code: str) -> str:
    """An example for the old Poppy Ergo with the Ergo Jr's motor names (its one adaptation)."""
    for old, new in ERGO_MOTOR_NAMES.items():
        code = code.replace(f".{old}.", f".{new}.")
    return code


# -- saving and loading a config (lines 3002-3017, 3116-3123) -----------------------------------

SAVE_CONFIG = """
import json

config = my_robot.to_config()

with open('myconfig.json', 'w') as f:
    json.dump(config, f, indent=2)
"""  # line 3002

LOAD_CONFIG = """
import json
import poppy_core.pypot

ergo = poppy_core.pypot.from_json('myconfig.json', use_dummy_io=True)
"""  # line 3014 (the documentation reads 'ergo.json'; `use_dummy_io`: no hardware here)

CLOSING = """
from contextlib import closing

import poppy_core.pypot

# The closing decorator make sure that the close function will be called
# on the object passed as argument when the with block is exited.

with closing(poppy_core.pypot.from_json('myconfig.json', use_dummy_io=True)) as my_robot:
    # do stuff without having to make sure not to forget to close my_robot!
    pass
"""  # line 3116

# -- a minimal config file (line 2570) ----------------------------------------------------------

MINIMAL_CONFIG_JSON = """
{
    "controllers": {
        "head_controller": {
            "sync_read": true,
            "attached_motors": [
                "head"
            ],
            "port": "auto"
        }
    },
    "motorgroups": {
        "head": [
            "head_z",
            "head_y"
        ]
    },
    "motors": {
        "head_y": {
            "offset": 20.0,
            "type": "AX-12",
            "id": 37,
            "angle_limit": [
                -40,
                8
            ],
            "orientation": "indirect"
        },
        "head_z": {
            "offset": 0.0,
            "type": "AX-12",
            "id": 36,
            "angle_limit": [
                -100,
                100
            ],
            "orientation": "direct"
        }
    }
}
"""  # line 2570 (its trailing comma after "head" dropped: JSON has none)

BASE_POSTURE = """
poppy.base_posture.start()
"""  # line 2037 ("so you can directly use `poppy.base_posture.start()`")
