"""One run of a sync loop on the bus: a register group read or written, offline motors pinged.

``BusSync`` (``robot.sync``) decides when each loop runs; this is what a run does. Reads go one
transaction per group of motors sharing a register layout (``DxlBus.sync_read``), each motor
decoding with its own registers; a motor's misses are counted until it goes offline, and an
offline motor that answers again is read whole the first time and resent its state. Writes send
what each motor's ``MotorLink`` holds pending, put back if the bus fails.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Sequence

from poppy_core.bus import DxlBus
from poppy_core.errors import BusError, MotorError, PortError
from poppy_core.models import ServoModel
from poppy_core.robot import registers as regs
from poppy_core.robot.loops import LoopSpec
from poppy_core.robot.motor import Motor
from poppy_core.robot.motor_link import link_of

logger = logging.getLogger(__name__)

RETRY = "retry"
# Offline motors are pinged RETRY_BATCH at a time, in turn, every ``retry_period_s`` (0.2 s): a
# motor plugged back answers within a fraction of a second, and a bus full of silent motors
# costs its live ones one ping per run.
RETRY_BATCH = 1


class SyncTransfers:
    """The bus transactions of one bus's sync loops.

    Args:
        bus: the bus.
        motors: the motors on it.
        offline_after: consecutive missed reads before a motor is marked offline.
        stopping: set when the loops stop (a round of pings ends early).
    """

    def __init__(
        self,
        bus: DxlBus,
        motors: Sequence[Motor],
        offline_after: int,
        stopping: threading.Event,
    ) -> None:
        self.bus = bus
        self.motors = motors
        self.offline_after = offline_after
        self._stop = stopping
        self._blocks: dict[tuple[str, ServoModel], list[regs.ReadBlock]] = {}
        self._retry_turn = 0

    def run(self, spec: LoopSpec) -> None:
        """Run loop ``spec`` once: its pings (``RETRY``), writes or reads."""
        if spec.name == RETRY:
            self.retry()
        elif spec.write:
            self.write(spec)
        else:
            self.read(spec)

    def _blocks_for(self, spec: LoopSpec, model: ServoModel) -> list[regs.ReadBlock]:
        key = (spec.name, model)
        if key not in self._blocks:
            self._blocks[key] = regs.read_blocks(model, spec.registers)
        return self._blocks[key]

    def read(self, spec: LoopSpec) -> None:
        """Read the registers of ``spec`` from every online motor into its link."""
        # Motors whose blocks share address and length go in one transaction, whatever their
        # model (AX and MX have the same layout); each decodes with its own registers.
        batches: dict[tuple[int, int], list[tuple[Motor, regs.ReadBlock]]] = {}
        for motor in self.motors:
            if motor.online:
                for block in self._blocks_for(spec, motor.model):
                    batches.setdefault((block.address, block.length), []).append((motor, block))
        for (address, length), members in batches.items():
            by_id = {motor.id: (motor, block) for motor, block in members}
            try:
                data = self.bus.sync_read(address, length, list(by_id))
            except MotorError as exc:
                member = by_id.get(exc.motor_id)
                self._missed(None if member is None else member[0], str(exc))
                raise
            for motor_id, payload in data.items():
                if motor_id not in by_id:
                    continue
                motor, block = by_id[motor_id]
                if payload is None or len(payload) != length:
                    self._missed(motor, f"no reply to the {spec.name} read")
                    continue
                link_of(motor).update(block.decode(payload))
                self._answered(motor)

    def _answered(self, motor: Motor) -> None:
        link = link_of(motor)
        if link.mark_answered():
            logger.info("%s (id %d) answers again", motor.name, motor.id)
            if link.cached("present_position") is None:
                self._first_state(motor)
            link.resend_state()

    def _first_state(self, motor: Motor) -> None:
        """Read the control table of a motor answering for the first time (the robot started
        without it: its bus or its power was not there yet)."""
        try:
            data = self.bus.read(motor.id, 0, motor.model.table_size)
        except PortError:
            raise
        except BusError as exc:
            logger.debug("%s: first state not read: %s", motor.name, exc)
            return
        link_of(motor).update(regs.decode_table(motor.model, data))

    def _missed(self, motor: Motor | None, reason: str) -> None:
        if motor is not None and link_of(motor).mark_missed(self.offline_after):
            logger.warning(
                "%s (id %d) on %s stopped answering (%s); pinging it until it answers",
                motor.name,
                motor.id,
                self.bus.port,
                reason,
            )

    def write(self, spec: LoopSpec) -> None:
        """Send the pending values of ``spec``'s registers of every online motor (sync writes);
        put them back when the bus fails."""
        taken: list[tuple[Motor, dict[str, int]]] = []
        for motor in self.motors:
            if motor.online:
                values = link_of(motor).take_pending(spec.registers)
                if values:
                    taken.append((motor, values))
        if not taken:
            return
        try:
            for name in spec.registers:
                groups: dict[tuple[int, int], dict[int, bytes]] = {}
                for motor, values in taken:
                    if name in values:
                        register = motor.model.register(name)
                        key = (register.address, register.size)
                        groups.setdefault(key, {})[motor.id] = register.encode(values[name])
                for (address, _), data in groups.items():
                    self.bus.sync_write(address, data)
        except BusError:
            for motor, values in taken:
                link_of(motor).restore_pending(values)
            raise

    def retry(self, every: bool = False) -> None:
        """Ping offline motors: the next ``RETRY_BATCH`` in turn, or ``every`` one of them."""
        offline = [m for m in self.motors if not m.online]
        if not offline:
            return
        if not every:
            start = self._retry_turn % len(offline)
            offline = (offline[start:] + offline[:start])[:RETRY_BATCH]
            self._retry_turn += len(offline)
        for motor in offline:
            if self._stop.is_set():
                return
            try:
                answered = self.bus.ping(motor.id, identify=False) is not None
            except PortError:
                raise
            except BusError:
                answered = False
            if answered:
                self._answered(motor)
