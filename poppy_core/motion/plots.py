"""Drawings with matplotlib, as pypot's ``Move.plot(ax)`` and ``chain.plot(joints, ax)`` made them.

matplotlib is imported only when a drawing is asked for; without an axis one is made on a figure
of its own (no display, no pyplot: ``fig.savefig`` writes it) and returned.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from poppy_core.errors import ArgumentError

if TYPE_CHECKING:
    from poppy_core.kinematics import Chain
    from poppy_core.motion.move import Move


def _new_axes(three_d: bool) -> Any:
    """An axis on a figure of its own, made without pyplot: the caller's backend is untouched."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(8, 4.5) if not three_d else (6, 6))
    return figure.add_subplot(projection="3d") if three_d else figure.add_subplot()


def plot_move(move: Move, ax: Any = None) -> Any:
    """Each motor's position (°) over time (s), one line per motor, labelled with its name.

    Returns:
        The axis drawn on (a new Agg one when ``ax`` is None).
    """
    axes = _new_axes(False) if ax is None else ax
    if len(move) == 0:
        return axes
    times = move.times()
    for column, name in enumerate(move.motors):
        axes.plot(times, move.positions[:, column], label=name)
    axes.set_xlabel("time (s)")
    axes.set_ylabel("position (°)")
    axes.legend(loc="upper right")
    return axes


def plot_chain(
    chain: Chain, joints_deg: Sequence[float], ax: Any = None, target: Any = None
) -> Any:
    """The chain as segments between its joints' origins and its tip, in metres, in 3D.

    Args:
        chain: the kinematic chain.
        joints_deg: one angle per joint, degrees (user frame).
        ax: a matplotlib 3D axis (``projection='3d'``), or None for a new one.
        target: an ``[x, y, z]`` to mark (pypot's ``target=``).

    Returns:
        The axis drawn on.
    """
    axes = _new_axes(True) if ax is None else ax
    if not hasattr(axes, "plot3D"):
        raise ArgumentError(
            "chain.plot draws in 3D: give an axis made with projection='3d' "
            "(fig.add_subplot(projection='3d')) or none",
            field="ax",
        )
    frames = chain.frames(list(joints_deg))
    points = np.array([np.zeros(3)] + [frame[:3, 3] for frame in frames.values()])
    axes.plot3D(points[:, 0], points[:, 1], points[:, 2], "o-", label=chain.name)
    if target is not None:
        x, y, z = (float(v) for v in np.asarray(target, dtype=float).reshape(3))
        axes.scatter([x], [y], [z], marker="x", color="red", label="target")
    axes.set_xlabel("x (m)")
    axes.set_ylabel("y (m)")
    axes.set_zlabel("z (m)")
    return axes
