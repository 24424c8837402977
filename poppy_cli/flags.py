"""The one table of `poppy`'s option names: each long flag's short flag, value and meaning.

Every option of every command is listed here (``tests/cli/test_flag_table.py`` walks the app and
checks it): a short flag stands for one long flag everywhere, and a long flag means one thing with
one unit. The help shows ``value`` after the flag (``--duration SECONDS``); docs/cli.md carries the
table as ``flag_table_markdown()`` renders it. Old spellings still accepted are in ``DEPRECATED``.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Flag:
    """One long flag: its short flag (or None), its value's name (None: an on/off flag), its
    meaning."""

    short: str | None
    value: str | None
    meaning: str


FLAGS: dict[str, Flag] = {
    # -- the root group
    "--debug": Flag(None, None, "show tracebacks and debug logs"),
    "--verbose": Flag("-v", None, "show info logs"),
    "--quiet": Flag("-q", None, "print only errors and the data asked for"),
    "--version": Flag("-V", None, "print poppy's version and exit"),
    "--install-completion": Flag(None, None, "install shell completion for the current shell"),
    "--show-completion": Flag(None, None, "print the completion script of the current shell"),
    # -- the robot a command drives
    "--profile": Flag(None, "PROFILE", "robot profile name (`poppy config list`)"),
    "--config": Flag("-c", "FILE", "robot config file (JSON or YAML)"),
    "--port": Flag(
        "-p", "PORT", "serial port of the bus: a device, a pty or a URL (`notebook`: its TCP port)"
    ),
    "--sim": Flag(None, "[mujoco]", "a virtual robot: bare for ideal servos, `mujoco` for physics"),
    "--remote": Flag(None, "URL", "drive a served robot: http://HOST:PORT or zenoh:NAME"),
    "--motors": Flag("-m", "MOTORS", "which motors: names or groups (models:IDs in `emulate`)"),
    "--chain": Flag(None, "NAME", "kinematic chain of the robot"),
    # -- the bus
    "--baud": Flag("-b", "BPS", "baud rate of the bus, in bits per second"),
    "--all-bauds": Flag(None, None, "try every standard baud rate"),
    "--target-baud": Flag(None, "BPS", "baud rate to give the motor, in bits per second"),
    "--protocol": Flag(None, "1|2", "Dynamixel protocol (`scan` also takes `both`)"),
    "--ids": Flag(None, "IDS", "motor IDs, e.g. 1-6 or 1,3,11-15"),
    "--model": Flag(None, "MODEL", "servo model, e.g. MX-28"),
    "--angle-limits": Flag(None, "MIN,MAX", "angle limits in degrees"),
    "--reset-id": Flag(None, None, "also reset the ID to the factory one"),
    "--reset-baudrate": Flag(None, None, "also reset the baud rate to the factory one"),
    "--zero": Flag(None, None, "move the motor to 0° afterwards"),
    # -- time and motion
    "--duration": Flag("-d", "SECONDS", "how long, in seconds"),
    "--freq": Flag(None, "HZ", "frames recorded per second"),
    "--rate": Flag(None, "HZ", "loop ticks per second"),
    "--ramp": Flag(None, "SECONDS", "ramp time to the first goal, in seconds"),
    "--speed": Flag("-s", "FACTOR", "speed factor: 2 is twice as fast, 1 real time"),
    "--loop": Flag("-l", "COUNT", "times to play"),
    "--reverse": Flag("-r", None, "play backwards"),
    "--wait": Flag(None, None, "wait until the motors arrived"),
    "--trajectory": Flag(None, "minjerk|dummy", "goto trajectory: minimum jerk or a jump"),
    "--linear": Flag(None, None, "move the tip along a straight line"),
    "--orientation": Flag(None, "X,Y,Z", "the tip's x axis"),
    "--rpy": Flag(None, "ROLL,PITCH,YAW", "the tip's orientation in degrees"),
    "--set": Flag(None, "PROPERTY=VALUE", "a primitive property set before it starts"),
    "--stiff": Flag(None, None, "turn the torque on before starting (`--keep-compliance`: not)"),
    "--keep-compliance": Flag(None, None, "leave the torque as it is (see `--stiff`)"),
    "--watch": Flag("-w", None, "keep refreshing until Ctrl-C"),
    "--tolerance": Flag(None, "DEGREES", "drift allowed, in degrees"),
    "--all-at-once": Flag(None, None, "move every joint through its range in one go"),
    "--check": Flag(None, None, "compare the robot to its calibration"),
    # -- teleoperation
    "--leader": Flag(None, "PROFILE|FILE", "the leader robot: a profile or a config file"),
    "--leader-port": Flag(None, "PORT", "serial port of the leader's bus"),
    "--follower": Flag(None, "PROFILE|FILE|URL", "the follower: a profile, a config or a URL"),
    "--follower-port": Flag(None, "PORT", "serial port of the follower's bus"),
    "--follower-sim": Flag(None, "[mujoco]", "a virtual follower, as `--sim`"),
    "--map": Flag(None, "MAP", "joint map FOLLOWER=[-][SCALE*]LEADER[+OFFSET],..."),
    "--map-file": Flag(None, "FILE", "joint map file (YAML)"),
    "--record": Flag(None, "NAME", "save the follower's trajectory as this move"),
    # -- files and names
    "--output": Flag("-o", "PATH", "file to write, or a folder"),
    "--force": Flag("-f", None, "replace an existing file or move"),
    "--yes": Flag("-y", None, "do not ask for confirmation"),
    "--name": Flag(
        "-n", "NAME", "name of what the command saves (a move, a profile), or the robot's name"
    ),
    "--prefix": Flag(None, "PREFIX", "motor name prefix (motors named PREFIX<ID>)"),
    "--format": Flag(None, "pypot|poppy", "move file format"),
    "--lang": Flag(None, "en|fr", "language"),
    "--move": Flag(None, "MOVE", "a move: library name or file"),
    # -- output
    "--json": Flag(None, None, "print JSON for scripts"),
    "--yaml": Flag(None, None, "print YAML"),
    # -- servers
    "--host": Flag(None, "HOST", "address to serve on, or of the server"),
    "--http": Flag(None, None, "serve the REST API"),
    "--http-port": Flag(None, "PORT", "TCP port of the web server"),
    "--ws": Flag(None, None, "stream the motors' state on a WebSocket"),
    "--ws-port": Flag(None, "PORT", "TCP port of the WebSocket"),
    "--ws-rate": Flag(None, "HZ", "WebSocket state frames per second"),
    "--zmq": Flag(None, None, "serve pypot's ZMQ API"),
    "--zmq-port": Flag(None, "PORT", "TCP port of the ZMQ API"),
    "--zenoh": Flag(None, None, "serve the robot on Zenoh under poppy/NAME (fleets)"),
    "--zenoh-listen": Flag(None, "ENDPOINT", "Zenoh endpoint to listen on, e.g. tcp/0.0.0.0:7447"),
    "--zenoh-connect": Flag(
        None, "ENDPOINT", "Zenoh peer or router to connect to (`--connect` in fleet, teleop)"
    ),
    "--zenoh-config": Flag(None, "FILE", "Zenoh's own JSON5 configuration (TLS, access control)"),
    "--zenoh-scout": Flag(None, None, "find Zenoh peers by multicast scouting on the LAN"),
    "--ros2": Flag(None, None, "serve the robot as a ROS 2 node over rmw_zenoh"),
    "--ros-domain": Flag(None, "N", "ROS 2 domain ID (0-232; ROS_DOMAIN_ID)"),
    "--ros-namespace": Flag(None, "NS", "the ROS 2 node's namespace, e.g. /lab"),
    "--foxglove": Flag(None, None, "serve the robot to the Foxglove app (foxglove-sdk)"),
    "--foxglove-port": Flag(None, "PORT", "TCP port of the Foxglove WebSocket server"),
    "--mcap": Flag(None, "FILE", "write what Foxglove shows to this MCAP file"),
    "--connect": Flag(
        None, "ENDPOINT", "`--zenoh-connect`'s other name in `fleet`, `teleop`, `dataset record`"
    ),
    "--listen": Flag(None, "ENDPOINT", "Zenoh endpoint the router listens on"),
    "--all": Flag(None, None, "every robot of the fleet"),
    "--robots": Flag(None, "NAMES", "robots of the fleet, comma-separated"),
    "--lead": Flag(None, "SECONDS", "seconds between a fleet command and its shared start"),
    "--snap": Flag(None, None, "serve pypot's Snap! routes and the Poppy blocks"),
    "--snap-port": Flag(None, "PORT", "TCP port of the Snap! server"),
    "--snap-dir": Flag(None, "DIR", "a downloaded Snap! to serve"),
    "--robot": Flag(None, "URL", "the served robot a notebook reaches (`poppy serve --http`)"),
    "--dir": Flag(None, "DIR", "folder of the notebooks"),
    "--no-browser": Flag(None, None, "do not open a web browser"),
    "--from": Flag(None, "URL", "where to download from: a URL, a file:// URL or a file"),
    "--sha256": Flag(None, "HEX", "the digest a download must have (64 hex digits)"),
    "--open": Flag(None, None, "open it in the web browser"),
    "--token": Flag(None, "TOKEN", "token every request must carry"),
    "--token-file": Flag(None, "FILE", "file holding the token every request must carry"),
    "--require-token": Flag(None, None, "require a token, kept in a file only the service reads"),
    "--settings": Flag(None, "FILE", "the installed service's options file (Snap!, ZMQ)"),
    "--url": Flag(None, "URL", "the robot's page, checked by `poppy doctor`"),
    "--cors": Flag(None, "ORIGIN", "web page origin allowed to use the robot"),
    "--allow-host": Flag(None, "HOST", "host name the server also answers"),
    "--no-sensors": Flag(None, None, "leave the config's cameras closed"),
    "--announce": Flag(None, None, "announce the robot's name over mDNS (NAME.local)"),
    "--no-announce": Flag(None, None, "do not announce it (see `--announce`)"),
    "--timeout": Flag(None, "SECONDS", "how long to wait, in seconds"),
    "--interface": Flag(None, "ADDRESS", "the network interface of this IPv4 address only"),
    "--wait-for-motors": Flag(None, None, "serve while the port or the motors are missing"),
    "--serve": Flag(None, None, "serve the app to a web browser"),
    # -- the boot service
    "--user": Flag(None, None, "the service of your own session instead of the system's"),
    "--run-as": Flag(None, "USER", "the user the system service runs as"),
    "--jupyter": Flag(None, None, "also start Jupyter at boot"),
    "--dry-run": Flag(None, None, "print what would be done, change nothing"),
    "--lines": Flag(None, "N", "last log lines shown"),
    "--follow": Flag(None, None, "keep showing new log lines"),
    # -- emulators and simulation
    "--pty": Flag(None, None, "serve on a pseudo-terminal (the default)"),
    "--tcp": Flag(None, "HOST:PORT", "serve on TCP instead"),
    "--link": Flag(None, "PATH", "a symlink kept pointing at the pty"),
    "--wire-timing": Flag(None, None, "delay replies as a real wire does"),
    "--no-wire-timing": Flag(None, None, "reply at once (see `--wire-timing`)"),
    "--latency-ms": Flag(None, "MS", "adapter latency added to replies, in milliseconds"),
    "--usb2ax": Flag(None, None, "act as a USB2AX adapter"),
    "--corrupt": Flag(None, "PROBABILITY", "fault: probability that a reply byte is flipped"),
    "--drop": Flag(None, "PROBABILITY", "fault: probability that a reply is lost"),
    "--delay-ms": Flag(None, "MS", "fault: delay added to every reply, in milliseconds"),
    "--unplug": Flag(None, "ID@T[+D]", "fault: unplug a motor T seconds after start"),
    "--control": Flag(None, None, "read fault and hand commands from stdin"),
    "--seed": Flag(None, "SEED", "seed of the random numbers"),
    "--quick": Flag(None, None, "ten times faster"),
    "--view": Flag(None, None, "open MuJoCo's viewer"),
    "--camera": Flag(
        None, "CAMERA", "a camera: of the simulation model; NAME[=SPEC] recorded in a dataset"
    ),
    "--width": Flag(None, "PIXELS", "image width in pixels"),
    "--height": Flag(None, "PIXELS", "image height in pixels"),
    # -- cameras
    "--device": Flag(None, "DEVICE", "camera: an index, a device path or a video file"),
    "--resolution": Flag(None, "WxH", "image size, e.g. 640x480"),
    "--marker": Flag(None, "ID", "an ArUco marker held in view of the simulated camera"),
    "--card": Flag(None, "CARD", "a Poppy card held in view of the simulated camera"),
    # -- datasets (poppy dataset record, replay, view, delete-episode)
    "--root": Flag(None, "DIR", "the dataset's folder"),
    "--resume": Flag(None, None, "add episodes to the dataset there"),
    "--play": Flag(None, "MOVE", "actions: play this move each episode"),
    "--primitive": Flag(None, "NAME", "actions: run this primitive each episode"),
    "--by-hand": Flag(None, None, "actions: the robot compliant, moved by hand"),
    "--episodes": Flag(None, "N", "episodes to record"),
    "--episode-s": Flag(None, "SECONDS", "length of an episode"),
    "--episode": Flag(None, "K", "an episode of the dataset, by its number (from 0)"),
    "--reset-s": Flag(None, "SECONDS", "pause between episodes"),
    "--task": Flag(None, "TEXT", "what the episodes show, in words"),
    "--fps": Flag(None, "N", "frames per second"),
    "--no-cameras": Flag(None, None, "record no camera"),
    "--rerun": Flag(None, "FILE", "write the episode to this Rerun file (.rrd)"),
    # -- Click's own
    "--help": Flag(None, None, "show the help and exit"),
}
"""Long flag -> its short flag, value and meaning."""


@dataclass(frozen=True)
class Alias:
    """An old spelling still accepted by one command: it works as ``new`` with a warning."""

    command: tuple[str, ...]
    old: str
    new: str


DEPRECATED: tuple[Alias, ...] = (
    Alias(("tui",), "--web-port", "--http-port"),
    Alias(("motor", "reset"), "--rate", "--target-baud"),
    Alias(("robot", "goto"), "--control", "--trajectory"),
    Alias(("config", "generate"), "--name", "--prefix"),
    Alias(("play",), "-n", "--loop"),
    Alias(("camera", "snapshot"), "-d", "--device"),
    Alias(("camera", "detect"), "-d", "--device"),
)
"""Spellings of earlier releases (README, docs, scripts), hidden from the help."""


def rewrite_deprecated(command: tuple[str, ...], args: list[str]) -> tuple[list[str], list[str]]:
    """``args`` of ``command`` with its deprecated spellings replaced; and one note per spelling.

    ``--old VALUE``, ``--old=VALUE`` and ``-xVALUE`` are rewritten; nothing after ``--``.
    """
    aliases = {alias.old: alias.new for alias in DEPRECATED if alias.command == command}
    if not aliases:
        return args, []
    out: list[str] = []
    notes: list[str] = []
    for index, token in enumerate(args):
        if token == "--":
            out.extend(args[index:])
            break
        old, new, rest = _match(token, aliases)
        if old is None:
            out.append(token)
            continue
        note = f"`{old}` is deprecated: use `{new}` (`poppy {' '.join(command)} --help`)"
        if note not in notes:
            notes.append(note)
        out.append(new if rest is None else f"{new}={rest}")
    return out, notes


def _match(token: str, aliases: dict[str, str]) -> tuple[str | None, str, str | None]:
    """The alias ``token`` spells, its new flag and the value written in the same word."""
    if token in aliases:
        return token, aliases[token], None
    for old, new in aliases.items():
        if old.startswith("--") and token.startswith(old + "="):
            return old, new, token[len(old) + 1 :]
        if not old.startswith("--") and token.startswith(old) and len(token) > len(old):
            return old, new, token[len(old) :].removeprefix("=")
    return None, "", None


def flag_table_markdown() -> str:
    """The table of docs/cli.md: the short flags, then one row per long flag, sorted by name."""
    shorts = sorted((flag.short, name) for name, flag in FLAGS.items() if flag.short)
    index = " · ".join(f"`{short}` `{name}`" for short, name in shorts)
    rows = [f"Short flags: {index}.", "", "| flag | short | value | meaning |", "|---|---|---|---|"]
    for name in sorted(FLAGS):
        flag = FLAGS[name]
        value = f"`{flag.value}`".replace("|", "\\|") if flag.value else ""
        short = f"`{flag.short}`" if flag.short else ""
        rows.append(f"| `{name}` | {short} | {value} | {flag.meaning} |")
    return "\n".join(rows)
