"""Scan results as a tree port → baud rate → motor; space marks motors for a multi-apply."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from textual.binding import Binding, BindingType
from textual.message import Message
from textual.widgets import Tree
from textual.widgets.tree import TreeNode

from poppy_cli.tui.busio import MotorRef

NodeData = MotorRef | None


def motor_label(motor: MotorRef, marked: bool) -> str:
    """``[x] id 3  XL-320  fw 39``."""
    box = "[x]" if marked else "[ ]"
    model = motor.model or "unknown model"
    firmware = "" if motor.firmware is None else f"  fw {motor.firmware}"
    return f"{box} id {motor.id:<3} {model}{firmware}"


class MotorTree(Tree[NodeData]):
    """Found motors; Enter opens one in the motor panel, space marks several."""

    BINDINGS: ClassVar[list[BindingType]] = [
        Binding("enter", "select_cursor", "Open"),
        Binding("space", "mark", "Mark"),
        Binding("a", "mark_all", "Mark all"),
    ]

    @dataclass
    class Opened(Message):
        """A motor was chosen (Enter or click); ``marked`` are the motors ticked with space."""

        motor: MotorRef
        marked: list[MotorRef]

    def __init__(self, *, id: str | None = None) -> None:
        super().__init__("buses", id=id)
        self.show_root = False
        self.guide_depth = 2
        self._marked: set[str] = set()
        self._ports: dict[str, TreeNode[NodeData]] = {}
        self._rates: dict[tuple[str, int, int], TreeNode[NodeData]] = {}
        self._motors: dict[str, TreeNode[NodeData]] = {}

    def add_motor(self, motor: MotorRef) -> None:
        """Add a found motor under its port and rate (nodes created as needed)."""
        if motor.key in self._motors:
            return
        port = self._ports.get(motor.port)
        if port is None:
            port = self.root.add(motor.port, expand=True)
            self._ports[motor.port] = port
        rate_key = (motor.port, motor.baudrate, motor.protocol)
        rate = self._rates.get(rate_key)
        if rate is None:
            rate = port.add(f"{motor.baudrate:,} bps · protocol {motor.protocol}", expand=True)
            self._rates[rate_key] = rate
        self._motors[motor.key] = rate.add_leaf(motor_label(motor, False), data=motor)

    def replace_motor(self, old: MotorRef, new: MotorRef) -> None:
        """Move a motor after an ID or baud-rate change."""
        node = self._motors.pop(old.key, None)
        was_marked = old.key in self._marked
        self._marked.discard(old.key)
        if node is not None:
            node.remove()
        self.add_motor(new)
        if was_marked:
            self._set_mark(new, True)

    def clear_motors(self) -> None:
        """Forget every motor (before a new scan)."""
        self.clear()
        self._marked.clear()
        self._ports.clear()
        self._rates.clear()
        self._motors.clear()

    @property
    def motors(self) -> list[MotorRef]:
        """Every motor in the tree."""
        return [node.data for node in self._motors.values() if node.data is not None]

    @property
    def marked(self) -> list[MotorRef]:
        """The motors marked with space."""
        return [motor for motor in self.motors if motor.key in self._marked]

    def _set_mark(self, motor: MotorRef, on: bool) -> None:
        if on:
            self._marked.add(motor.key)
        else:
            self._marked.discard(motor.key)
        node = self._motors.get(motor.key)
        if node is not None:
            node.set_label(motor_label(motor, on))

    def action_mark(self) -> None:
        """Mark or unmark the motor under the cursor (a port or rate node folds instead)."""
        node = self.cursor_node
        if node is None:
            return
        if node.data is None:
            node.toggle()
            return
        self._set_mark(node.data, node.data.key not in self._marked)

    def action_mark_all(self) -> None:
        """Mark every motor, or none when all are marked."""
        everyone = self.motors
        on = len(self._marked) < len(everyone)
        for motor in everyone:
            self._set_mark(motor, on)

    def on_tree_node_selected(self, event: Tree.NodeSelected[NodeData]) -> None:
        event.stop()
        if event.node.data is not None:
            self.post_message(self.Opened(event.node.data, self.marked))
