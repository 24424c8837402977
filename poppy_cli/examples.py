"""The Examples section of every command's help: command lines that work, each with its purpose.

``tests/cli/test_help_pages.py`` checks that every command has examples and that each one parses
against the command it shows (flags and arguments as they are today).
"""

from __future__ import annotations

from rich.markup import escape

Example = tuple[str, str]
"""A command line (without the leading `poppy`) and what it does."""

EXAMPLES: dict[str, tuple[Example, ...]] = {
    "": (
        ("demo", "a virtual Ergo Jr: scan it, show it, make it dance"),
        ("ports", "serial ports and the Dynamixel adapters among them"),
        ("robot status --profile ergo-jr --sim", "a virtual robot's motors"),
    ),
    "ports": (("ports", "every serial port, adapters first"), ("ports --json", "for scripts")),
    "scan": (
        ("scan --port /dev/ttyUSB0", "IDs 0-253 at 1 Mbps, protocols 1 and 2"),
        ("scan -p /dev/ttyUSB0 --all-bauds --ids 1-6", "every standard rate, IDs 1-6"),
        ("scan -p /dev/ttyUSB0 -b 57600 -b 1000000 --protocol 1 --json", "two rates, JSON"),
    ),
    "emulate": (
        ("emulate --profile ergo-jr", "six virtual XL-320; prints the pty to use as --port"),
        ("emulate -m MX-28:11-15,AX-12A:36-37 --tcp 127.0.0.1:4000", "any motors, on TCP"),
        ("emulate --profile ergo-jr --control", "type faults on stdin: unplug 3, drop 0.05"),
    ),
    "demo": (
        ("demo", "the whole tour on a virtual Ergo Jr"),
        ("demo --quick", "ten times faster"),
        ("demo --sim mujoco", "the dance with MuJoCo physics"),
    ),
    "tui": (
        ("tui --sim", "a virtual Ergo Jr in the terminal"),
        ("tui -p /dev/ttyUSB0", "open and scan this bus at start"),
        ("tui --serve --http-port 8000", "the same app in a web browser"),
    ),
    "record": (
        ("record wave --profile ergo-jr -p /dev/ttyUSB0", "move the arm by hand; Enter stops"),
        ("record wave --profile ergo-jr --sim -d 5 -f", "5 s, replacing a move named wave"),
        ("record wave --profile ergo-jr -p /dev/ttyUSB0 -m base --freq 20", "some motors"),
    ),
    "play": (
        ("play wave --profile ergo-jr --sim", "play a move of the library"),
        ("play wave -s 2 -l 3 --profile ergo-jr -p /dev/ttyUSB0", "twice as fast, 3 times"),
        ("play ./wave.json -r --remote http://poppy.local:8080", "backwards, on a served robot"),
    ),
    "dataset": (
        (
            "dataset record me/pick --profile ergo-jr -p /dev/ttyUSB1 --leader ergo-jr"
            " --leader-port /dev/ttyUSB0 --episodes 10 --task 'pick the cube'",
            "ten teleoperated episodes with the robot's camera",
        ),
        ("dataset info ~/.cache/huggingface/lerobot/me/pick", "episodes, frames, tasks"),
    ),
    "dataset record": (
        (
            "dataset record me/pick --profile ergo-jr -p /dev/ttyUSB1 --leader ergo-jr"
            " --leader-port /dev/ttyUSB0 --episodes 10 --task 'pick the cube'",
            "a leader arm moved by a student, the follower and its camera recorded",
        ),
        (
            "dataset record me/wave --profile ergo-jr -p /dev/ttyUSB0 --by-hand --task wave"
            " --episode-s 10",
            "the robot compliant, moved by hand",
        ),
        (
            "dataset record me/dance --profile ergo-jr --sim mujoco --primitive dance"
            " --episodes 5 --task dance --root ./dance",
            "data from the simulation, its camera rendered",
        ),
    ),
    "dataset info": (
        ("dataset info ./dance", "episodes, frames, duration, tasks, cameras"),
        ("dataset info ./dance --json", "for scripts"),
    ),
    "dataset list": (
        ("dataset list ./dance", "one row per episode"),
        ("dataset list ./dance --json", "for scripts"),
    ),
    "dataset replay": (
        (
            "dataset replay me/pick --episode 3 --profile ergo-jr -p /dev/ttyUSB1",
            "ramp to the first frame, play the actions",
        ),
        ("dataset replay me/dance --root ./dance --episode 0 --sim --speed 0.5", "half speed"),
    ),
    "dataset delete-episode": (
        ("dataset delete-episode me/pick --episode 3", "the later episodes move down"),
    ),
    "dataset view": (
        ("dataset view me/pick --episode 3 --mcap pick-3.mcap", "for Foxglove: Open local file"),
        (
            "dataset view me/dance --root ./dance --episode 0 --mcap dance.mcap --force",
            "replace the file",
        ),
        ("dataset view me/pick --episode 3 --rerun pick-3.rrd", "for Rerun: rerun pick-3.rrd"),
    ),
    "calibrate": (
        ("calibrate --profile ergo-jr -p /dev/ttyUSB0", "zeros and ranges into a user profile"),
        ("calibrate --profile ergo-jr -p /dev/ttyUSB0 --check", "report the drift since"),
        ("calibrate --profile ergo-jr --sim -m m1,m2 -y -n my-ergo", "two virtual joints"),
    ),
    "teleop": (
        (
            "teleop --leader ergo-jr --leader-port /dev/ttyUSB0 --follower ergo-jr --follower-sim",
            "a virtual follower copies the real leader",
        ),
        (
            "teleop --leader ergo-jr --leader-port /dev/ttyUSB0"
            " --follower http://poppy.local:8080 --rate 50",
            "drive a served robot",
        ),
        (
            "teleop --follower ergo-jr --follower-sim mujoco -d 30 --record take -f",
            "the leader of the user settings; 30 s saved as the move take",
        ),
    ),
    "serve": (
        ("serve --http --profile ergo-jr --sim", "the REST API and web page on port 8080"),
        ("serve --snap --open --profile ergo-jr -p /dev/ttyUSB0", "Snap! with the Poppy blocks"),
        ("serve --http --http-port 9000 --ws --token s3cret --profile ergo-jr --sim", "a token"),
        (
            "serve --http --host 0.0.0.0 --name poppy --announce --token s3cret --profile ergo-jr",
            "http://poppy.local:8080 on the network",
        ),
        (
            "serve --zenoh --name jr1 --zenoh-connect tcp/192.168.1.10:7447 --profile ergo-jr",
            "on Zenoh as poppy/jr1, through the teacher's router",
        ),
        (
            "serve --ros2 --name jr1 --ros-namespace /lab --profile ergo-jr",
            "a ROS 2 node /lab/jr1, through the zenohd router on this computer",
        ),
        (
            "serve --http --settings serve.json --token-file token --profile ergo-jr --sim",
            "options and token from files, as the installed service (not in `ps`)",
        ),
    ),
    "fleet": (
        ("fleet discover", "the robots announced on the network (mDNS)"),
        ("fleet list --connect tcp/192.168.1.10:7447", "the robots on Zenoh"),
        ("fleet play wave --all", "every robot plays a move, starting together"),
        ("fleet stop --all", "the Stop button of every robot"),
        ("fleet serve", "the teacher's page: every robot's card, play and Stop for all"),
    ),
    "fleet discover": (
        ("fleet discover", "listen 3 s on every interface"),
        ("fleet discover --timeout 1 --interface 127.0.0.1 --json", "this machine's only"),
    ),
    "fleet serve": (
        ("fleet serve", "the teacher's page on http://127.0.0.1:8090/, robots via a local router"),
        (
            "fleet serve --host 0.0.0.0 --token-file ~/.poppy-token",
            "on the classroom's network, with the robots' token",
        ),
    ),
    "fleet router": (
        ("fleet router", "a Zenoh router on port 7447 of every interface, until Ctrl-C"),
        ("fleet router --listen tcp/192.168.1.10:7447", "on the classroom's interface only"),
    ),
    "fleet list": (
        ("fleet list", "through a router on this computer (tcp/127.0.0.1:7447)"),
        ("fleet list --connect tcp/192.168.1.10:7447 --json", "for scripts"),
    ),
    "fleet status": (
        ("fleet status --watch", "one live table of every robot"),
        ("fleet status --connect tcp/192.168.1.10:7447", "once"),
    ),
    "fleet run": (
        ("fleet run dance --all", "every robot dances, starting together"),
        ("fleet run dance --robots jr1,jr2", "two robots"),
    ),
    "fleet play": (
        ("fleet play wave --all", "every robot plays a move of its library"),
        ("fleet play wave --robots jr1,jr2 --token s3cret", "two robots served with a token"),
        ("fleet play wave --all --ramp 2", "each robot reaches the first frame in 2 s: in phase"),
    ),
    "fleet stop": (
        ("fleet stop --all", "primitives and moves stopped, motors held"),
        ("fleet stop --robots jr3 --json", "one robot, JSON"),
    ),
    "motor": (
        ("motor info 3 -p /dev/ttyUSB0", "the whole control table"),
        ("motor get 1-6 present_position -p /dev/ttyUSB0", "read a register of six motors"),
        ("motor set-id 1 11 -p /dev/ttyUSB0 -b 57600 --protocol 1", "a new ID, verified"),
    ),
    "motor info": (
        ("motor info 3 -p /dev/ttyUSB0", "model, firmware and control table"),
        ("motor info 3 -p /dev/ttyUSB0 -b 1000000 --protocol 2 --json", "no search; JSON"),
    ),
    "motor get": (
        ("motor get 3 present_position -p /dev/ttyUSB0", "degrees"),
        ("motor get 1-6 present_position present_temperature -p /dev/ttyUSB0 --json", "JSON"),
    ),
    "motor set": (
        ("motor set 3 torque_enable on -p /dev/ttyUSB0", "stiff"),
        ("motor set 3 goal_position 30 -p /dev/ttyUSB0", "move (torque must be on)"),
        ("motor set 1,3,5 moving_speed 60 -p /dev/ttyUSB0", "60 deg/s on three motors"),
    ),
    "motor torque": (
        ("motor torque 1-6 on -p /dev/ttyUSB0", "stiff"),
        ("motor torque 3 off -p /dev/ttyUSB0", "compliant: move it by hand"),
    ),
    "motor led": (
        ("motor led 1-6 on -p /dev/ttyUSB0", "lights on"),
        ("motor led 3 green -p /dev/ttyUSB0", "a colour on an XL-320"),
    ),
    "motor set-id": (
        ("motor set-id 1 11 -p /dev/ttyUSB0", "motor 1 becomes 11"),
        ("motor set-id 1 11 -p /dev/ttyUSB0 -b 57600 --protocol 1", "no search"),
    ),
    "motor set-baudrate": (
        ("motor set-baudrate 11 1000000 -p /dev/ttyUSB0", "1 Mbps, checked at the new rate"),
    ),
    "motor set-return-delay": (
        ("motor set-return-delay 3 0 -p /dev/ttyUSB0", "answer at once (Poppy robots)"),
    ),
    "motor angle-limits": (
        ("motor angle-limits 3 -p /dev/ttyUSB0", "show them"),
        ("motor angle-limits 3 -p /dev/ttyUSB0 -- -90 90", "set them (`--` before -90)"),
    ),
    "motor reboot": (("motor reboot 3 -p /dev/ttyUSB0", "clears a hardware alarm"),),
    "motor factory-reset": (
        ("motor factory-reset 3 -p /dev/ttyUSB0", "asks first; keeps ID and baud rate"),
        ("motor factory-reset 3 --reset-id --reset-baudrate -y -p /dev/ttyUSB0", "everything"),
    ),
    "setup": (("setup motors --profile ergo-jr -p /dev/ttyAMA0", "a kit's motors, one at a time"),),
    "setup motors": (
        ("setup motors --profile ergo-jr -p /dev/ttyAMA0", "each motor: plug only it, Enter"),
        ("setup motors --profile ergo-jr -m m3 -p /dev/ttyUSB0", "set up (or fix) m3 alone"),
        ("setup motors --profile ergo-jr -m m1 -p /dev/ttyUSB0 --json", "what was done, JSON"),
    ),
    "doctor": (
        ("doctor --profile ergo-jr -p /dev/ttyAMA0", "one line per check, with its fix"),
        ("doctor --profile ergo-jr --json", "for scripts: {ok, checks}"),
        ("doctor --profile ergo-jr --url http://127.0.0.1:8080/", "the page on another port"),
    ),
    "motor reset": (
        ("motor reset 1 42 -p /dev/ttyUSB0", "a new motor becomes 42, 1 Mbps, delay 0"),
        ("motor reset 1 42 --model MX-28 --angle-limits -150,150 --zero -p /dev/ttyUSB0", ""),
        ("motor reset 1 42 --target-baud 57600 -p /dev/ttyUSB0", "another baud rate"),
    ),
    "config": (
        ("config list", "installed and user profiles"),
        ("config show ergo-jr", "a profile's motors and groups"),
        ("config generate -p /dev/ttyUSB0 -o my_robot.yaml", "a config of the motors found"),
    ),
    "config validate": (("config validate my_robot.yaml", "one line per problem"),),
    "config convert": (
        ("config convert poppy_ergo_jr.json ergo.yaml", "pypot JSON to YAML"),
        ("config convert ergo.yaml ergo.json -f", "back, replacing the file"),
    ),
    "config show": (("config show ergo-jr", "a profile"), ("config show my.yaml --json", "JSON")),
    "config list": (("config list", "profiles"), ("config list --json", "for scripts")),
    "config set": (
        ("config set profile ergo-jr", "the default robot of every command"),
        ("config set port /dev/ttyUSB0", "its default serial port"),
    ),
    "config get": (("config get profile", "one setting"), ("config get --json", "all of them")),
    "config unset": (("config unset port", "back to no default port"),),
    "config path": (
        ("config path", "where the settings and profiles live"),
        ("config path ergo-jr --json", "the file a profile resolves to"),
    ),
    "config generate": (
        ("config generate -p /dev/ttyUSB0 -o my_robot.yaml", "scan and write"),
        ("config generate -p /dev/ttyUSB0 -b 1000000 --protocol 2 --prefix joint -o .", ""),
    ),
    "robot": (
        ("robot status --profile ergo-jr --sim", "every motor of a virtual Ergo Jr"),
        ("robot goto m1=30 m2=-10 -d 2 --profile ergo-jr -p /dev/ttyUSB0", "move two motors"),
        ("robot compliant off --profile ergo-jr -p /dev/ttyUSB0", "every motor stiff"),
    ),
    "robot status": (
        ("robot status --profile ergo-jr -p /dev/ttyUSB0", "a table of every motor"),
        ("robot status --profile ergo-jr --sim -w", "refreshed until Ctrl-C"),
        ("robot status --remote http://poppy.local:8080 --json", "a served robot, JSON"),
    ),
    "robot goto": (
        ("robot goto m1=30 m2=-10 -d 2 --profile ergo-jr -p /dev/ttyUSB0", "arrive together"),
        ("robot goto m1=0 --trajectory dummy --wait --profile ergo-jr --sim", "a plain jump"),
        ("robot goto m6=-20 --sim mujoco --profile ergo-jr", "with MuJoCo physics"),
    ),
    "robot compliant": (
        ("robot compliant on --profile ergo-jr -p /dev/ttyUSB0", "move it by hand"),
        ("robot compliant off m1 m2 --profile ergo-jr -p /dev/ttyUSB0", "two motors stiff"),
    ),
    "robot where": (
        ("robot where --profile ergo-jr --sim", "the tip of each chain"),
        ("robot where --profile ergo-jr -p /dev/ttyUSB0 --json", "JSON"),
    ),
    "robot reach": (
        ("robot reach 0.1 -0.1 0.12 --profile ergo-jr --sim", "the tip to x, y, z (metres)"),
        ("robot reach 0.1 0 0.15 --linear -d 2 --wait --profile ergo-jr --sim", "a line"),
    ),
    "primitive": (
        ("primitive list --profile ergo-jr --sim", "what a robot can run"),
        ("primitive run sinus -d 5 --set amplitude=20 --profile ergo-jr --sim", "a sine"),
    ),
    "primitive list": (
        ("primitive list --profile ergo-jr --sim", "state, properties, last error"),
        ("primitive list --remote http://poppy.local:8080 --json", "of a served robot"),
    ),
    "primitive run": (
        ("primitive run sinus -d 5 --set amplitude=20 --profile ergo-jr --sim", "5 s of sine"),
        ("primitive run dance --profile ergo-jr -p /dev/ttyUSB0", "the Ergo Jr's dance"),
    ),
    "moves": (
        ("moves list", "the library"),
        ("moves show wave", "header and statistics of a move"),
        ("moves export wave -o wave.json", "in pypot's format"),
    ),
    "moves list": (("moves list", "name, motors, duration, size"), ("moves list --json", "")),
    "moves show": (("moves show wave", "per-motor statistics"), ("moves show ./w.json --json", "")),
    "moves plot": (("moves plot wave -o wave.png", "each motor against time"),),
    "moves rm": (("moves rm wave", "asks first"), ("moves rm wave -y", "no question")),
    "moves export": (
        ("moves export wave -o wave.json", "pypot's JSON, for old tools"),
        ("moves export wave -o . --format poppy -f", "poppy's format into this folder"),
    ),
    "moves import": (
        ("moves import mymove.json", "named after the file"),
        ("moves import mymove.json -n old-wave -f", "another name, replacing it"),
    ),
    "sim": (
        ("sim --profile ergo-jr", "serve the simulated robot's bus (prints its pty)"),
        ("sim --profile humanoid -s 0.5 --view", "half speed, in MuJoCo's viewer"),
        ("sim render --profile humanoid -o humanoid.png", "a picture"),
    ),
    "sim render": (
        ("sim render --profile humanoid -o humanoid.png", "a still"),
        ("sim render --profile ergo-jr --move wave -o wave.gif -f", "a move, as a GIF"),
        ("sim render --profile torso --camera side -o torso-side.png", "from its left"),
        ("sim render --profile ergo-jr --camera free --width 320 --height 240 -o .", ""),
    ),
    "snap": (
        ("snap blocks -o poppy-blocks.xml --profile ergo-jr", "the Poppy blocks"),
        ("snap project first-steps -o . --profile ergo-jr", "an example project"),
        ("snap download", "Snap! itself, once, for offline classes"),
    ),
    "notebook": (
        ("notebook", 'Jupyter with the "Discover your robot" notebook (robot on :8080)'),
        ("notebook --robot http://poppy.local:8080", "notebooks driving a robot on the network"),
        ("notebook --host 0.0.0.0 --port 8888 --no-browser", "as the robot's service runs it"),
    ),
    "snap download": (
        ("snap download", "the pinned Snap! release, once (then `serve --snap` is offline)"),
        ("snap download --from file:///media/usb/Snap-11.0.8.zip", "from a USB stick"),
        ("snap download 11.0.8 --from https://mirror.example/Snap.zip --force", "a mirror"),
    ),
    "snap blocks": (
        ("snap blocks -o . --profile ergo-jr", "into this folder"),
        ("snap blocks -o blocks.xml --lang fr --host poppy.local --snap-port 6969", "French"),
    ),
    "snap project": (
        ("snap project first-steps -o . --profile ergo-jr", "a first project"),
        ("snap project record-replay-fr -o rr.xml --profile ergo-jr -f", "in French"),
    ),
    "service": (
        ("service install --port /dev/ttyAMA0", "serve the Ergo Jr at boot: http://poppy.local"),
        ("service status", "installed? running?"),
        ("service release", "free the motors' port for a notebook"),
    ),
    "service install": (
        ("service install --port /dev/ttyAMA0 --snap", "at boot, with Snap!, on a Pi"),
        ("service install --user --dry-run", "print the unit of a desktop service"),
        ("service install --name ergo-2 --jupyter --run-as pi", "a second robot, Jupyter too"),
        ("service install --port /dev/ttyAMA0 --require-token", "with a token the page changes"),
    ),
    "service status": (
        ("service status", "the system's service"),
        ("service status --user --json", "your session's, for scripts"),
    ),
    "service logs": (
        ("service logs", "its last 50 lines"),
        ("service logs --lines 200 --follow", "and the new ones as they come"),
    ),
    "service restart": (("service restart", "after an update"),),
    "service stop": (("service stop", "until the next boot"),),
    "service uninstall": (("service uninstall --user", "remove your session's service"),),
    "service release": (
        ("service release", "the robot of this machine lets go of its motors"),
        ("service release --remote http://poppy.local --json", "another robot's, for scripts"),
    ),
    "service take": (
        ("service take", "take the motors back"),
        ("service take --remote http://ergo-2.local", "another robot's"),
    ),
    "camera": (
        ("camera list", "video devices"),
        ("camera snapshot -o frame.png", "one frame of /dev/video0"),
        ("camera detect --profile ergo-jr --sim mujoco --marker 7", "markers, in simulation"),
    ),
    "camera list": (("camera list", "V4L2 devices and names"), ("camera list --json", "")),
    "camera snapshot": (
        ("camera snapshot -o frame.png", "/dev/video0"),
        ("camera snapshot -o frame.jpg --device 1 --resolution 640x480", "another camera"),
        ("camera snapshot -o sim.png --profile ergo-jr --sim mujoco --card caribou", "in sim"),
    ),
    "camera detect": (
        ("camera detect", "markers seen by /dev/video0"),
        ("camera detect --device 1 -w --json", "keep detecting (JSON each time)"),
        ("camera detect --profile ergo-jr --sim mujoco --marker 7", "a simulated marker"),
    ),
}
"""Command path (words after `poppy`, "" for the root) -> its examples."""


ALIGNED_WIDTH = 88
"""Examples whose lines fit in this width get their purpose on the same line, aligned."""


def examples_epilog(path: str) -> str | None:
    """The help's Examples section of command ``path`` (Rich markup), or None when it has none."""
    examples = EXAMPLES.get(path)
    if not examples:
        return None
    commands = [f"$ poppy {line}" for line, _ in examples]
    width = max(len(command) for command in commands)
    aligned = all(width + 4 + len(purpose) <= ALIGNED_WIDTH for _, purpose in examples)
    lines = ["[bold]Examples[/bold]"]
    for command, (_, purpose) in zip(commands, examples, strict=True):
        if not purpose:
            lines.append(escape(command))
        elif aligned:
            lines.append(escape(f"{command.ljust(width)}  # {purpose}"))
        else:
            lines += [escape(f"# {purpose}"), escape(command)]
    return "\n".join(lines)
