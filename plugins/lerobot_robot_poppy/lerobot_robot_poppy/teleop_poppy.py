"""Poppy robots as LeRobot leaders: `poppy_ergo_jr_leader`, `poppy_torso_leader` (its arms),
`poppy_humanoid_leader` (its arms).

The action is the leader's joint positions in degrees, ``NAME.pos``, the follower's action
names. Torque: ``connect`` makes the leader's joints compliant, to be moved by hand (or, with
``primitive``, stiff and moved by that primitive: a simulated leader has no hand to move it);
``disconnect`` stops the primitive and leaves the joints compliant.
"""

from __future__ import annotations

import logging
from functools import cached_property
from typing import Any

from lerobot.processor import RobotAction
from lerobot.teleoperators import Teleoperator
from lerobot.utils.decorators import check_if_already_connected, check_if_not_connected

from lerobot_robot_poppy import calibration, link
from lerobot_robot_poppy.config_poppy import (
    PoppyErgoJrLeaderConfig,
    PoppyHumanoidLeaderConfig,
    PoppyLeaderFields,
    PoppyTorsoLeaderConfig,
)

logger = logging.getLogger(__name__)


class PoppyLeader(Teleoperator):
    """A Poppy robot (or some of its joints) whose positions lead a follower."""

    config_class: type[Any] = PoppyLeaderFields
    name = "poppy_leader"
    kind = "poppy_ergo_jr"

    def __init__(self, config: Any) -> None:
        super().__init__(config)
        self.config = config
        self.poppy_config = link.load_config(config.profile, self.kind)
        self.joints = link.joints(self.poppy_config, config.group)
        self._link: Any = None
        self._primitive: Any = None

    @cached_property
    def action_features(self) -> dict[str, type]:
        return {f"{name}.pos": float for name in self.joints}

    @cached_property
    def feedback_features(self) -> dict[str, type]:
        return {}

    @property
    def is_connected(self) -> bool:
        return self._link is not None

    @property
    def is_calibrated(self) -> bool:
        """As the follower's (see ``PoppyRobot.is_calibrated``)."""
        if link.is_remote(self.config.port):
            return True
        return set(self.joints) <= set(self.calibration)

    def calibrate(self) -> None:
        """Write LeRobot's calibration file from poppy's config (see ``PoppyRobot.calibrate``)."""
        if link.is_remote(self.config.port):
            return
        self.calibration = {
            **self.calibration,
            **calibration.from_poppy(self.poppy_config, self.joints),
        }
        self._save_calibration()

    @check_if_already_connected
    def connect(self, calibrate: bool = True) -> None:
        if not self.is_calibrated and calibrate:
            self.calibrate()
        config = self.poppy_config
        if self.calibration and not link.is_remote(self.config.port):
            config = calibration.apply(config, self.calibration)
        self._link = link.open_link(
            config, self.config.port, self.joints, [], self.config.zenoh_connect
        )
        try:
            self.configure()
        except BaseException:
            self._link.close()
            self._link = None
            raise
        logger.info("%s connected on %s", self, self.config.port)

    def configure(self) -> None:
        """Compliant joints (moved by hand), or the primitive started."""
        if self.config.primitive:
            self._link.set_compliant(self.joints, False)
            self._primitive = self._link.start_primitive(self.config.primitive)
        else:
            self._link.set_compliant(self.joints, True)

    @check_if_not_connected
    def get_action(self) -> RobotAction:
        return {f"{n}.pos": v for n, v in self._link.positions(self.joints).items()}

    def send_feedback(self, feedback: dict[str, Any]) -> None:
        """No feedback: a Poppy leader has no force feedback."""

    @check_if_not_connected
    def disconnect(self) -> None:
        try:
            if self._primitive is not None:
                self._primitive.stop()
                self._primitive = None
            self._link.set_compliant(self.joints, True)
        finally:
            self._link.close()
            self._link = None


class PoppyErgoJrLeader(PoppyLeader):
    """An Ergo Jr leading an Ergo Jr."""

    config_class = PoppyErgoJrLeaderConfig
    name = "poppy_ergo_jr_leader"
    kind = "poppy_ergo_jr"


class PoppyTorsoLeader(PoppyLeader):
    """A Torso's arms leading a Torso's."""

    config_class = PoppyTorsoLeaderConfig
    name = "poppy_torso_leader"
    kind = "poppy_torso"


class PoppyHumanoidLeader(PoppyLeader):
    """A Humanoid's arms leading a Humanoid's."""

    config_class = PoppyHumanoidLeaderConfig
    name = "poppy_humanoid_leader"
    kind = "poppy_humanoid"
