"""The Poppy blocks for Snap! as data: label (English, French), inputs, URL template, answer kind.

A template names the route a block calls, with ``{input}`` where an input goes; ``each`` names an
input holding several motors (``m1;m2`` or ``m1 m2``): the block calls the route once per motor,
the motor in ``{motor}``. ``blocks.py`` turns these into Snap! XML; the tests call every
template on a served robot. Labels use ``%'name'`` for inputs, as Snap! does.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

Kind = Literal["command", "reporter", "predicate"]
Answer = Literal["done", "text", "names", "values", "numbers", "number", "bool"]
"""How a block reads the answer: ``names`` split at ``/``, ``values`` at ``;``, ``numbers`` at
``,``; ``done`` (commands) shows the answer only when it is an error."""


@dataclass(frozen=True)
class Input:
    """One input slot: its name, Snap! slot type (``%s``, ``%n``, ``%b``) and default key."""

    name: str
    slot: str = "%s"
    default: str = ""
    """A literal, or ``@motor``, ``@motors``, ``@group``, ``@primitive``, ``@chain``, ``@move``,
    ``@moves``, ``@card``, ``@x``/``@y``/``@z`` filled from the served robot."""


@dataclass(frozen=True)
class SnapBlock:
    """A Poppy block."""

    key: str
    kind: Kind
    category: str
    en: str
    fr: str
    inputs: tuple[Input, ...]
    template: str
    answer: Answer = "done"
    each: str | None = None
    help_en: str = ""


M = Input("motors", "%s", "@motors")
ONE = Input("motor", "%s", "@motor")

BLOCKS: tuple[SnapBlock, ...] = (
    SnapBlock(
        "connected",
        "predicate",
        "sensing",
        "robot connected?",
        "robot connecté ?",
        (),
        "/connected",
        "bool",
        help_en="True when the robot's server answers at host:port ('set robot host to').",
    ),
    SnapBlock(
        "motors",
        "reporter",
        "sensing",
        "all motors",
        "tous les moteurs",
        (),
        "/motors/motors",
        "names",
        help_en="The robot's motors (a list).",
    ),
    SnapBlock(
        "group",
        "reporter",
        "sensing",
        "motors of group %'group'",
        "moteurs du groupe %'group'",
        (Input("group", "%s", "@group"),),
        "/motors/{group}",
        "names",
    ),
    SnapBlock(
        "index",
        "reporter",
        "sensing",
        "index of motor %'motor'",
        "numéro du moteur %'motor'",
        (ONE,),
        "/motor/{motor}/index",
        "number",
        help_en="Its place in 'all motors' and 'positions of all motors' (from 1).",
    ),
    SnapBlock(
        "groups",
        "reporter",
        "sensing",
        "all motor groups",
        "tous les groupes de moteurs",
        (),
        "/motors/alias",
        "names",
    ),
    SnapBlock(
        "positions",
        "reporter",
        "sensing",
        "positions of all motors",
        "positions de tous les moteurs",
        (),
        "/motors/get/positions",
        "values",
        help_en="Present positions (degrees), in the order of 'all motors'.",
    ),
    SnapBlock(
        "read",
        "reporter",
        "sensing",
        "%'register' of motor %'motor'",
        "%'register' du moteur %'motor'",
        (Input("register", "%s", "present_position"), ONE),
        "/motor/{motor}/get/{register}",
        "text",
    ),
    SnapBlock(
        "read_many",
        "reporter",
        "sensing",
        "%'register' of motors %'motors'",
        "%'register' des moteurs %'motors'",
        (Input("register", "%s", "present_position"), M),
        "/motors/{motors}/get/{register}",
        "values",
    ),
    SnapBlock(
        "compliant",
        "command",
        "motion",
        "set motors %'motors' compliant %'compliant'",
        "mettre les moteurs %'motors' souples %'compliant'",
        (M, Input("compliant", "%b", "false")),
        "/motor/{motor}/set/compliant/{compliant}",
        each="motors",
        help_en="Compliant (true): free to move by hand; false: stiff.",
    ),
    SnapBlock(
        "goto",
        "command",
        "motion",
        "move motors %'motors' to %'position' ° in %'duration' s",
        "tourner les moteurs %'motors' à %'position' ° en %'duration' s",
        (M, Input("position", "%n", "0"), Input("duration", "%n", "1")),
        "/motor/{motor}/goto/{position}/{duration}",
        each="motors",
    ),
    SnapBlock(
        "goto_many",
        "command",
        "motion",
        "move motors %'settings' (motor:angle:seconds;...)",
        "tourner les moteurs %'settings' (moteur:angle:secondes;...)",
        (Input("settings", "%s", "@gotos"),),
        "/motors/set/goto/{settings}",
    ),
    SnapBlock(
        "set",
        "command",
        "motion",
        "set %'register' of motors %'motors' to %'value'",
        "mettre %'register' des moteurs %'motors' à %'value'",
        (Input("register", "%s", "goal_position"), M, Input("value", "%s", "0")),
        "/motor/{motor}/set/{register}/{value}",
        each="motors",
    ),
    SnapBlock(
        "led",
        "command",
        "looks",
        "set LED of motors %'motors' to %'color'",
        "allumer la LED des moteurs %'motors' en %'color'",
        (M, Input("color", "%s", "green")),
        "/motor/{motor}/set/led/{color}",
        each="motors",
        help_en="Colours: off, red, green, yellow, blue, pink, cyan, white.",
    ),
    SnapBlock(
        "primitives",
        "reporter",
        "sensing",
        "all behaviours",
        "tous les comportements",
        (),
        "/primitives",
        "names",
    ),
    SnapBlock(
        "running",
        "reporter",
        "sensing",
        "running behaviours",
        "comportements en cours",
        (),
        "/primitives/running",
        "names",
    ),
    SnapBlock(
        "primitive",
        "command",
        "control",
        "%'action' behaviour %'primitive'",
        "%'action' le comportement %'primitive'",
        (Input("action", "%s", "start"), Input("primitive", "%s", "@primitive")),
        "/primitive/{primitive}/{action}",
        help_en="Actions: start, stop, pause, resume.",
    ),
    SnapBlock(
        "property",
        "reporter",
        "sensing",
        "%'property' of behaviour %'primitive'",
        "%'property' du comportement %'primitive'",
        (Input("property", "%s", "@property"), Input("primitive", "%s", "@primitive")),
        "/primitive/{primitive}/get/{property}",
        "text",
    ),
    SnapBlock(
        "record",
        "command",
        "control",
        "start recording move %'move' with motors %'motors'",
        "enregistrer le mouvement %'move' des moteurs %'motors'",
        (Input("move", "%s", "@move"), M),
        "/primitive/MoveRecorder/{move}/start/{motors}",
        help_en="Make the motors compliant first to move them by hand.",
    ),
    SnapBlock(
        "save",
        "command",
        "control",
        "stop recording and save move %'move'",
        "arrêter et sauver le mouvement %'move'",
        (Input("move", "%s", "@move"),),
        "/primitive/MoveRecorder/{move}/stop",
        help_en="Saved in the move library, beside the moves of 'poppy record'.",
    ),
    SnapBlock(
        "moves",
        "reporter",
        "sensing",
        "all recorded moves",
        "tous les mouvements enregistrés",
        (),
        "/primitive/MovePlayer",
        "names",
    ),
    SnapBlock(
        "play",
        "reporter",
        "control",
        "play move %'move' at speed × %'speed'",
        "jouer le mouvement %'move' à la vitesse × %'speed'",
        (Input("move", "%s", "@move"), Input("speed", "%n", "1")),
        "/primitive/MovePlayer/{move}/start/{speed}",
        "number",
        help_en="Starts the move and reports its duration (s).",
    ),
    SnapBlock(
        "play_back",
        "reporter",
        "control",
        "play move %'move' backwards at speed × %'speed'",
        "jouer le mouvement %'move' à l'envers à la vitesse × %'speed'",
        (Input("move", "%s", "@move"), Input("speed", "%n", "1")),
        "/primitive/MovePlayer/{move}/start/{speed}/backwards",
        "number",
    ),
    SnapBlock(
        "play_together",
        "reporter",
        "control",
        "play moves %'moves' together at speed × %'speed'",
        "jouer les mouvements %'moves' ensemble à la vitesse × %'speed'",
        (Input("moves", "%s", "@moves"), Input("speed", "%n", "1")),
        "/moves/concurrently/{moves}/{speed}",
        "number",
        help_en="Starts every move (m1;m2) at once; reports the longest duration (s).",
    ),
    SnapBlock(
        "play_sequence",
        "reporter",
        "control",
        "play moves %'moves' one after the other at speed × %'speed'",
        "jouer les mouvements %'moves' l'un après l'autre à la vitesse × %'speed'",
        (Input("moves", "%s", "@moves"), Input("speed", "%n", "1")),
        "/moves/sequentially/{moves}/{speed}",
        "number",
        help_en="Plays the moves (m1;m2) in turn; reports the total duration (s).",
    ),
    SnapBlock(
        "stop_move",
        "command",
        "control",
        "stop move %'move'",
        "arrêter le mouvement %'move'",
        (Input("move", "%s", "@move"),),
        "/primitive/MovePlayer/{move}/stop",
    ),
    SnapBlock(
        "remove",
        "command",
        "control",
        "delete move %'move'",
        "effacer le mouvement %'move'",
        (Input("move", "%s", "@move"),),
        "/primitive/MoveRecorder/{move}/remove",
    ),
    SnapBlock(
        "detect",
        "predicate",
        "sensing",
        "card %'card' detected?",
        "carte %'card' détectée ?",
        (Input("card", "%s", "@card"),),
        "/detect/{card}",
        "bool",
        help_en="Cards: caribou, tetris, lapin (rabbit).",
    ),
    SnapBlock(
        "tip",
        "reporter",
        "sensing",
        "tip position of chain %'chain'",
        "position du bout de la chaîne %'chain'",
        (Input("chain", "%s", "@chain"),),
        "/ik/{chain}/endeffector",
        "numbers",
        help_en="x, y, z in metres.",
    ),
    SnapBlock(
        "ik_goto",
        "command",
        "motion",
        "move tip of chain %'chain' to x %'x' y %'y' z %'z' in %'duration' s",
        "amener le bout de la chaîne %'chain' à x %'x' y %'y' z %'z' en %'duration' s",
        (
            Input("chain", "%s", "@chain"),
            Input("x", "%n", "@x"),
            Input("y", "%n", "@y"),
            Input("z", "%n", "@z"),
            Input("duration", "%n", "1"),
        ),
        "/ik/{chain}/goto/{x}/{y}/{z}/{duration}",
        help_en="Metres, in the robot's base frame.",
    ),
    SnapBlock(
        "reset",
        "command",
        "control",
        "reset simulation",
        "réinitialiser la simulation",
        (),
        "/reset-simulation",
    ),
    SnapBlock(
        "ip", "reporter", "sensing", "robot IP address", "adresse IP du robot", (), "/ip/", "text"
    ),
)
"""Every block, in palette order."""
