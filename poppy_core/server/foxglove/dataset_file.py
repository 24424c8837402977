"""A recorded episode of a LeRobot dataset as an MCAP file Foxglove opens
(``poppy dataset view --mcap``).

The channels and schemas are ``poppy record --mcap``'s (``FoxglovePublisher``), stamped with
the dataset's frame timestamps (seconds from the episode's start, as nanoseconds from 0):

- ``/joint_states`` (``foxglove.JointStates``): ``observation.state`` as joint angles (rad);
- ``/action`` (``foxglove.JointStates``): ``action`` the same way;
- ``/tf`` (``foxglove.FrameTransforms``): the URDF's tree at the state's angles;
- ``/robot_description`` (the URDF) and ``/robot_model`` (its meshes embedded), once;
- ``/NAME/image`` (``foxglove.CompressedImage``): each camera's frames as JPEG;
- ``/task`` (``foxglove.Log``): the episode's task, once.

The URDF and the motors' joint frames come from a profile (the dataset's ``robot_type``, or
the one given); without one, ``/joint_states`` and ``/action`` hold the degrees as radians and
there is no ``/tf`` nor model. The file is written beside the target under a temporary name and
put in place when whole.
"""

from __future__ import annotations

import contextlib
import os
import secrets
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import foxglove
from foxglove import Channel, Context
from foxglove.channels import (
    CompressedImageChannel,
    FrameTransformsChannel,
    JointStatesChannel,
    LogChannel,
    SceneUpdateChannel,
)
from foxglove.messages import Log, LogLevel

from poppy_core.dataset.episode import Episode, video_frames
from poppy_core.dataset.video import JpegEncoder
from poppy_core.errors import FileError
from poppy_core.files import file_error, output_path, place_file
from poppy_core.server.foxglove import robot_messages as messages
from poppy_core.server.foxglove.assets import RobotAssets
from poppy_core.server.foxglove.model_scene import model_scene
from poppy_core.server.foxglove.publisher import description_channel
from poppy_core.server.ros2.joints import UrdfJoints

if TYPE_CHECKING:
    from poppy_core.robot.config import RobotConfig


@dataclass(frozen=True)
class McapExport:
    """What was written: the file and the messages of each topic."""

    path: Path
    messages: dict[str, int]


def nanoseconds(seconds: float) -> int:
    """A frame's timestamp (s from the episode's start) as an MCAP log time."""
    return max(0, round(seconds * 1e9))


def write_episode_mcap(
    episode: Episode,
    path: str | os.PathLike[str],
    config: RobotConfig | None,
    *,
    replace: bool = False,
) -> McapExport:
    """Write ``episode`` into the MCAP file ``path``, with the robot model of ``config``.

    Raises:
        FileError: the target cannot be written (a missing folder, a file there without
            ``replace``, a full disk...); a file there before is left as it was.
    """
    target = output_path(path, replace=replace)
    temp = target.parent / f".{target.name[:200]}.{secrets.token_hex(6)}.tmp"
    context = Context()
    try:
        writer = foxglove.open_mcap(temp, context=context)
    except (OSError, RuntimeError) as exc:
        raise FileError(f"cannot write {target}: {exc}", path=str(target)) from None
    try:
        channels = _EpisodeChannels(episode, context, config)
        try:
            counts = channels.log_all()
        finally:
            writer.close()
            channels.close()
        place_file(temp, target, replace=replace)
    except OSError as exc:
        raise file_error(exc, target, "write") from None
    except RuntimeError as exc:  # the SDK's FoxgloveError (a full disk...)
        raise FileError(f"cannot write {target}: {exc}", path=str(target)) from None
    finally:
        with contextlib.suppress(OSError):
            os.unlink(temp)
    return McapExport(target, counts)


class _EpisodeChannels:
    """The episode's channels of one context, and the logging of every message in time order."""

    def __init__(self, episode: Episode, context: Context, config: RobotConfig | None) -> None:
        self.episode = episode
        self.joints = UrdfJoints.of_config(config, episode.motors)
        self.states = JointStatesChannel("/joint_states", context=context)
        self.action = JointStatesChannel("/action", context=context)
        self.task = LogChannel("/task", context=context)
        self.tf: FrameTransformsChannel | None = None
        self.description: Channel | None = None
        self.model: SceneUpdateChannel | None = None
        self.assets: RobotAssets | None = None
        if self.joints.description is not None:
            self.tf = FrameTransformsChannel("/tf", context=context)
            if self.joints.urdf is not None:
                self.assets = RobotAssets(Path(self.joints.description.source), self.joints.urdf)
                self.model = SceneUpdateChannel("/robot_model", context=context)
                self.description = description_channel(context)
        self.cameras = {
            video.camera: CompressedImageChannel(f"/{video.camera}/image", context=context)
            for video in episode.videos
        }
        self.counts: dict[str, int] = {c.topic(): 0 for c in self._channels()}

    def _channels(self) -> list[Any]:
        channels: list[Any] = [self.states, self.action, self.tf, self.description, self.model]
        channels += [self.task, *self.cameras.values()]
        return [c for c in channels if c is not None]

    def close(self) -> None:
        for channel in self._channels():
            channel.close()

    def _log(self, channel: Any, message: Any, seconds: float) -> None:
        channel.log(message, log_time=nanoseconds(seconds))
        self.counts[channel.topic()] += 1

    def log_all(self) -> dict[str, int]:
        """Every message, in the order of their timestamps; the counts per topic."""
        episode = self.episode
        start = float(episode.timestamps[0])
        self._log_once(start)
        videos = {v.camera: video_frames(episode, v) for v in episode.videos}
        pending = {camera: next(frames, None) for camera, frames in videos.items()}
        jpeg = {camera: JpegEncoder() for camera in videos}
        for k, seconds in enumerate(float(t) for t in episode.timestamps):
            state = dict(zip(episode.motors, episode.states[k].tolist(), strict=True))
            action = dict(zip(episode.motors, episode.actions[k].tolist(), strict=True))
            self._log(
                self.states, messages.positions_joint_states(self.joints, state, seconds), seconds
            )
            self._log(
                self.action, messages.positions_joint_states(self.joints, action, seconds), seconds
            )
            if self.tf is not None:
                self._log(
                    self.tf, messages.positions_transforms(self.joints, state, seconds), seconds
                )
            for camera, frames in videos.items():
                while (picture := pending[camera]) is not None and picture[0] <= k:
                    at = float(episode.timestamps[picture[0]])
                    image = messages.compressed_image(jpeg[camera].encode(picture[1]), camera, at)
                    self._log(self.cameras[camera], image, at)
                    pending[camera] = next(frames, None)
        return dict(self.counts)

    def _log_once(self, start: float) -> None:
        """The URDF, the robot's meshes and the task, at the episode's first frame."""
        if self.description is not None:
            self._log(self.description, {"data": self.joints.urdf}, start)
        if self.model is not None and self.assets is not None and self.joints.urdf is not None:
            self._log(self.model, model_scene(self.joints.urdf, self.assets, start), start)
        text = "; ".join(self.episode.tasks) or "(no task)"
        line = Log(
            timestamp=messages.stamp(start),
            level=LogLevel.Info,
            message=f"episode {self.episode.index}: {text}",
            name=self.episode.robot_type or "poppy",
        )
        self._log(self.task, line, start)
