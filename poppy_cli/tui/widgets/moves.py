"""Robot tab, Moves view: record compliant motors into the move library, play a move back."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)

from __future__ import annotations

import math
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path
from typing import TYPE_CHECKING, ClassVar

from textual import on, work
from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Horizontal, Vertical
from textual.message import Message
from textual.widgets import Button, DataTable, Input, ProgressBar, Select, Static

from poppy_cli.tui.messages import BusFailed
from poppy_core.errors import ConfigError, PoppyError

if TYPE_CHECKING:
    from poppy_core.motion import MovePlayer, MoveRecorder, PlayProgress
    from poppy_core.robot import Motor, Robot

RECORD_FREQ_HZ = 50.0
"""Frames per second of a recording (``poppy record``'s default)."""
MOVE_COLUMNS = ("move", "format", "size")


@dataclass
class MoveSaved(Message):
    """A recording was stopped and saved to the library."""

    path: Path
    frames: int
    duration_s: float


@dataclass
class PlayStarted(Message):
    """A move player runs (in its own thread)."""

    player: MovePlayer
    name: str


def parse_speed(text: str) -> float:
    """The play speed factor typed by the user (empty: 1.0).

    Raises:
        ConfigError: not a positive finite number.
    """
    try:
        speed = float(text.strip() or "1")
    except ValueError:
        raise ConfigError(f"speed {text!r} is not a number", field="speed") from None
    if not (math.isfinite(speed) and speed > 0):
        raise ConfigError(f"speed must be a positive number, got {text!r}", field="speed")
    return speed


def size_text(size_bytes: int) -> str:
    """A file size for the table (``812 B``, ``3.1 kB``, ``2.4 MB``)."""
    if size_bytes < 1000:
        return f"{size_bytes} B"
    if size_bytes < 1_000_000:
        return f"{size_bytes / 1000:.1f} kB"
    return f"{size_bytes / 1_000_000:.1f} MB"


class MovesPanel(Vertical):
    """Record and play moves; recorder and players run their own threads, polled by ``poll``."""

    BINDINGS: ClassVar[list[BindingType]] = [
        Binding("r", "record", "Record"),
        Binding("p", "play", "Play"),
        Binding("x", "stop", "Stop"),
    ]

    def __init__(self, *, id: str | None = None) -> None:
        super().__init__(id=id)
        self.robot: Robot | None = None
        self.recorder: MoveRecorder | None = None
        self.recording_name = ""
        self.player: MovePlayer | None = None
        self.playing_name = ""
        self.progress: PlayProgress | None = None
        """The player's last report (written by its thread, read by ``poll``)."""

    def compose(self) -> ComposeResult:
        with Horizontal(classes="row"):
            yield Input(placeholder="new move name", id="move-name")
            yield Select[str]([("all", "*")], value="*", allow_blank=False, id="record-group")
            yield Button("Record", id="move-record", variant="error")
        yield DataTable[str](id="moves-table", cursor_type="row", zebra_stripes=True)
        with Horizontal(classes="row"):
            yield Input("1.0", id="play-speed", type="number", tooltip="play speed factor")
            yield Button("Play", id="move-play", variant="primary")
            yield Button("Stop", id="move-stop")
            yield ProgressBar(total=1.0, show_eta=False, id="play-progress")
        yield Static("", id="move-status")

    def on_mount(self) -> None:
        table = self.query_one("#moves-table", DataTable)
        for column in MOVE_COLUMNS:
            table.add_column(column, key=column)
        self.reload()

    # -- robot and library -----------------------------------------------------------------

    def release(self) -> None:
        """Forget the robot (it is being closed): a recording is dropped, a playback stopped.

        Touches no widget, so it is safe while the app shuts down.
        """
        if self.recorder is not None:
            self.recorder.stop()
            self.recorder = None
            self.notify(f"recording {self.recording_name!r} dropped", severity="warning")
        if self.player is not None:
            self.player.stop()
            self.player = None
        self.robot = None

    def set_robot(self, robot: Robot) -> None:
        """Use ``robot`` (its groups are offered for recording) instead of the previous one."""
        self.release()
        self.robot = robot
        groups = [("all", "*"), *((name, name) for name in robot.motorgroups)]
        select = self.query_one("#record-group", Select)
        select.set_options(groups)
        select.value = "*"
        self._show_buttons()
        self.query_one("#move-status", Static).update("")

    def reload(self, select: Path | None = None) -> None:
        """List the library's moves again (the cursor goes to ``select`` when given)."""
        from poppy_core.motion import list_moves

        table = self.query_one("#moves-table", DataTable)
        table.clear()
        for entry in list_moves():
            table.add_row(
                entry.name, entry.format, size_text(entry.size_bytes), key=str(entry.path)
            )
        if select is not None and str(select) in {str(k.value) for k in table.rows}:
            table.move_cursor(row=table.get_row_index(str(select)))

    @property
    def selected(self) -> Path | None:
        """The file of the move under the cursor."""
        table = self.query_one("#moves-table", DataTable)
        if table.row_count == 0:
            return None
        return Path(str(table.coordinate_to_cell_key(table.cursor_coordinate).row_key.value))

    def _group_motors(self, robot: Robot) -> list[Motor]:
        choice = self.query_one("#record-group", Select).value
        if isinstance(choice, str) and choice != "*":
            return robot.group(choice)
        return list(robot.motors)

    # -- record ----------------------------------------------------------------------------

    def action_record(self) -> None:
        """Start recording (the motors turn compliant), or stop and save the recording."""
        if self.recorder is not None:
            self._save(self.recorder, self.recording_name)
            self.recorder = None
            self._show_buttons()
            return
        robot = self.robot
        if robot is None:
            self.notify("open a robot first", severity="warning")
            return
        if self.player is not None:
            self.notify("a move is playing: stop it first", severity="warning")
            return
        from poppy_core.motion import MoveRecorder, move_path

        name = self.query_one("#move-name", Input).value.strip()
        name = name or datetime.now().strftime("move-%Y%m%d-%H%M%S")
        try:
            path = move_path(name, must_exist=False)
            if path.exists():
                raise ConfigError(f"move {name!r} exists ({path}): choose another name")
            motors = self._group_motors(robot)
            recorder = MoveRecorder(robot, RECORD_FREQ_HZ, [m.name for m in motors])
        except (PoppyError, ValueError) as exc:
            self.notify(str(exc), severity="error")
            return
        for motor in motors:
            motor.compliant = True  # free to move by hand (the sync loop writes it)
        self.recorder = recorder.start()
        self.recording_name = name
        self._show_buttons()
        self.notify(f"recording {name!r}: {len(motors)} compliant motors; r or x saves it")

    @work(thread=True, group="moves", exit_on_error=False)
    def _save(self, recorder: MoveRecorder, name: str) -> None:
        """Stop the recorder (joins its thread) and write the move, off the UI thread."""
        from poppy_core.motion import save_move

        try:
            move = recorder.stop()
            if len(move) == 0:
                self.post_message(BusFailed(f"recording {name!r} has no frame: nothing saved"))
                return
            path = save_move(move, name)
        except (PoppyError, OSError, ValueError) as exc:
            self.post_message(BusFailed(f"cannot save move {name!r}: {exc}"))
            return
        self.post_message(MoveSaved(path, len(move), move.duration_s))

    @on(MoveSaved)
    def _saved(self, message: MoveSaved) -> None:
        message.stop()
        self.query_one("#move-status", Static).update(
            f"saved {message.path.name}: {message.frames} frames, {message.duration_s:.1f} s"
        )
        self.notify(f"move saved: {message.path}")
        self.reload(select=message.path)

    # -- play ------------------------------------------------------------------------------

    def action_play(self) -> None:
        """Play the move under the cursor at the typed speed."""
        robot = self.robot
        path = self.selected
        if robot is None:
            self.notify("open a robot first", severity="warning")
            return
        if path is None:
            self.notify("no move in the library: record one first", severity="warning")
            return
        if self.recorder is not None or self.player is not None:
            self.notify("stop the recording or playback first", severity="warning")
            return
        try:
            speed = parse_speed(self.query_one("#play-speed", Input).value)
        except ConfigError as exc:
            self.notify(str(exc), severity="error")
            return
        self.progress = None
        self.query_one("#play-progress", ProgressBar).update(progress=0.0)
        self._start_player(robot, path, speed)

    @work(thread=True, group="moves", exit_on_error=False)
    def _start_player(self, robot: Robot, path: Path, speed: float) -> None:
        """Load the move and start its player (reading the file stays off the UI thread)."""
        from poppy_core.motion import MovePlayer, load_move
        from poppy_core.motion.leases import Lease, motor_leases

        try:
            player = MovePlayer(robot, load_move(path), speed, on_progress=self._on_progress)
            # shown as the motors' owner ("move NAME from poppy tui") while it plays; a
            # Python-side player writes as pypot's do (never refused)
            lease = Lease(
                "move", path.stem, "poppy tui", stop="Stop in the TUI", alive=lambda: player.playing
            )
            player.start()
            motor_leases(robot).take(lease, list(player.played.motors), strict=False)
        except (PoppyError, ValueError, RuntimeError) as exc:
            self.post_message(BusFailed(f"cannot play {path.stem}: {exc}"))
            return
        self.post_message(PlayStarted(player, path.stem))

    def _on_progress(self, progress: PlayProgress) -> None:
        self.progress = progress  # the player's thread: an attribute, polled by the UI

    @on(PlayStarted)
    def _play_started(self, message: PlayStarted) -> None:
        message.stop()
        if message.player.robot is not self.robot:  # the robot changed meanwhile
            message.player.stop()
            return
        self.player = message.player
        self.playing_name = message.name
        self._show_buttons()

    def action_stop(self) -> None:
        """Stop the recording (it is saved) or the playback (the motors stay stiff)."""
        if self.recorder is not None:
            self.action_record()
        elif self.player is not None:
            self._stop_player(self.player)
        else:
            self.notify("nothing is recording or playing", severity="warning")

    @work(thread=True, group="moves", exit_on_error=False)
    def _stop_player(self, player: MovePlayer) -> None:
        player.stop()

    # -- polled by the robot panel's timer ---------------------------------------------------

    def poll(self) -> None:
        """Show the recording's or the playback's progress; notice a playback's end."""
        status = self.query_one("#move-status", Static)
        recorder = self.recorder
        if recorder is not None:
            status.update(
                f"● recording {self.recording_name}: {recorder.elapsed_s:.1f} s, "
                f"{recorder.frames_recorded} frames"
            )
            return
        player = self.player
        if player is None:
            return
        progress = self.progress
        if progress is not None:
            self.query_one("#play-progress", ProgressBar).update(progress=progress.fraction)
            status.update(
                f"▶ {self.playing_name}: {progress.phase}, "
                f"{progress.move_t_s:.1f}/{player.move.duration_s:.1f} s"
            )
        if player.playing:
            return
        self.player = None
        self._show_buttons()
        if player.error is not None:
            self.notify(f"playing {self.playing_name} failed: {player.error}", severity="error")
            status.update(f"{self.playing_name}: failed")
        else:
            word = "stopped" if player.stopped else "played"
            status.update(f"{self.playing_name}: {word} ({player.played_s:.1f} s)")
            self.notify(f"{self.playing_name}: {word}")

    def _show_buttons(self) -> None:
        record = self.query_one("#move-record", Button)
        record.label = "Save" if self.recorder is not None else "Record"
        self.query_one("#move-play", Button).disabled = self.player is not None

    # -- buttons -----------------------------------------------------------------------------

    @on(Button.Pressed, "#move-record")
    @on(Input.Submitted, "#move-name")
    def _record_pressed(self) -> None:
        self.action_record()

    @on(Button.Pressed, "#move-play")
    @on(Input.Submitted, "#play-speed")
    @on(DataTable.RowSelected, "#moves-table")
    def _play_pressed(self) -> None:
        self.action_play()

    @on(Button.Pressed, "#move-stop")
    def _stop_pressed(self) -> None:
        self.action_stop()
