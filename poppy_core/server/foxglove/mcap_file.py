"""``McapRecording``: the robot's Foxglove channels written to an MCAP file
(``poppy record --mcap FILE``).

The file gets what a Foxglove client would (``FoxglovePublisher``: joint states, transforms, the
URDF, health, cameras and detections, skeletons, IMUs) and the URDF's meshes embedded
(``/robot_model``), written by foxglove-sdk's MCAP writer into a temporary file beside the
target, put in place when the recording stops: a file at the target is always a whole MCAP file
(the one there before, when the recording failed).
"""

from __future__ import annotations

import contextlib
import os
import secrets
from pathlib import Path
from typing import TYPE_CHECKING

import foxglove
from foxglove import Context

from poppy_core.errors import FileError
from poppy_core.files import file_error, output_path, place_file
from poppy_core.server.foxglove.publisher import FoxglovePublisher

if TYPE_CHECKING:
    from poppy_core.robot import Robot


class McapRecording:
    """Record ``robot``'s Foxglove channels into ``path`` from ``start`` to ``stop``.

    Args:
        robot: the robot recorded.
        path: the MCAP file to write (checked now: a missing folder or an existing file
            without ``replace`` is a FileError before anything runs).
        name: the robot's name (in the health log).
        state_rate_hz: joint states and transforms per second.
        replace: an existing file may be replaced.
    """

    def __init__(
        self,
        robot: Robot,
        path: str | os.PathLike[str],
        name: str,
        *,
        state_rate_hz: float = 50.0,
        replace: bool = False,
    ) -> None:
        self.path = output_path(path, replace=replace)
        self.replace = replace
        self.context = Context()
        self.publisher = FoxglovePublisher(
            robot, self.context, name, state_rate_hz=state_rate_hz, embed_model=True
        )
        self._temp = self.path.parent / f".{self.path.name[:200]}.{secrets.token_hex(6)}.tmp"
        self._writer: foxglove.MCAPWriter | None = None

    @property
    def topics(self) -> list[str]:
        """The channels recorded."""
        return self.publisher.topics

    def start(self) -> McapRecording:
        """Open the file and record in the background.

        Raises:
            FileError: the temporary file cannot be created.
        """
        try:
            self._writer = foxglove.open_mcap(self._temp, context=self.context)
        except (OSError, RuntimeError) as exc:
            self.publisher.close()
            raise FileError(f"cannot write {self.path}: {exc}", path=str(self.path)) from None
        self.publisher.start()
        return self

    def stop(self) -> Path:
        """Stop recording, finish the file and put it in place.

        Returns:
            The file written.

        Raises:
            FileError: it could not be finished or put in place (the temporary file is removed).
        """
        self.publisher.stop()
        writer, self._writer = self._writer, None
        try:
            if writer is None:
                raise FileError(f"{self.path}: the recording never started", path=str(self.path))
            try:
                writer.close()
                self.publisher.close()
                place_file(self._temp, self.path, replace=self.replace)
            except OSError as exc:
                raise file_error(exc, self.path, "write") from None
            except RuntimeError as exc:  # the SDK's FoxgloveError (a full disk...)
                raise FileError(f"cannot write {self.path}: {exc}", path=str(self.path)) from None
        finally:
            with contextlib.suppress(OSError):
                os.unlink(self._temp)
        return self.path

    def __enter__(self) -> McapRecording:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        if self._writer is not None:
            self.stop()
