"""VirtualMotor: one emulated servo that keeps a control table and answers instruction packets."""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterable

from poppy_core.emulator.faults import fault_bits, shutdown_register_names
from poppy_core.emulator.table import ControlTable
from poppy_core.errors import ProtocolError
from poppy_core.models import ServoModel
from poppy_core.protocol import (
    BROADCAST_ID,
    Instruction,
    InstructionPacket,
    StatusPacket,
    parse_clear,
    parse_read,
    parse_write,
    protocol_for,
)

logger = logging.getLogger(__name__)

# Constant sensor values of an idle servo at its nominal voltage (e-manual "Specifications").
AMBIENT_TEMPERATURE_C = 35.0
_NOMINAL_VOLTAGE_V = {"XL-320": 7.4, "XL330": 5.0}
DEFAULT_VOLTAGE_V = 12.0
# The e-manual leaves the firmware version open ("-"): any plausible number will do.
DEFAULT_FIRMWARE = {1: 36, 2: 45}

# e-manual (Protocol 2.0, Factory Reset): option bytes.
_RESET_ALL = 0xFF
_RESET_KEEP_ID = 0x01
_RESET_KEEP_ID_BAUD = 0x02

HandMover = Callable[["VirtualMotor", float], None]


def nominal_voltage_v(model: ServoModel) -> float:
    """Nominal supply voltage the emulator reports for ``model``."""
    for prefix, volts in _NOMINAL_VOLTAGE_V.items():
        if model.name.upper().startswith(prefix.upper()):
            return volts
    return DEFAULT_VOLTAGE_V


class VirtualMotor:
    """An emulated Dynamixel servo.

    Args:
        model: the servo model (control table, protocol, limits).
        motor_id: the id written in its control table.
        baudrate_bps: its baud rate; None keeps the model's factory baud rate.

    Attributes:
        model: the servo model.
        protocol: 1 or 2 (from the model).
        proto: the protocol object (``poppy_core.protocol``).
        table: the control table (raw bytes plus write checks).
        lock: guards the table; the bus replaces it with its own lock.
        hand_mover: hook a plant sets to take over :meth:`move_by_hand` (e.g. a physics engine).
        hand_deg: where a hand holds the horn (degrees), None when no hand holds it; the
            plant reads it and ``hand_speed_dps`` (see :meth:`hold_by_hand`).
    """

    def __init__(self, model: ServoModel, motor_id: int, baudrate_bps: int | None = None) -> None:
        self.model = model
        self.protocol = model.protocol
        self.proto = protocol_for(model.protocol)
        self.table = ControlTable(model)
        self.lock: threading.RLock = threading.RLock()
        self.hand_mover: HandMover | None = None
        self.hand_deg: float | None = None
        self.hand_speed_dps = 0.0
        self._registered: tuple[int, bytes] | None = None
        self._fault_bits = 0
        if self.table.get("firmware") == 0:
            self.table.set("firmware", DEFAULT_FIRMWARE[self.protocol])
        self.table.set("id", motor_id)
        if baudrate_bps is not None:
            self.table.set("baudrate", model.baudrate_code(baudrate_bps))
        self._power_on_sensors()

    def __repr__(self) -> str:
        return f"VirtualMotor({self.model.name}, id={self.id}, {self.baudrate_bps} bps)"

    # ------------------------------------------------------------------ state

    def _power_on_sensors(self) -> None:
        table = self.table
        table.set_si("present_temperature", AMBIENT_TEMPERATURE_C)
        table.set_si("present_voltage", nominal_voltage_v(self.model))
        if table.get_si("present_position") is not None and table.get("present_position") == 0:
            table.set_si("present_position", 0.0)
        table.set("goal_position", table.get("present_position"))

    @property
    def id(self) -> int:
        """Current id (from the control table)."""
        return self.table.get("id")

    @property
    def baudrate_bps(self) -> int:
        """Current baud rate in bit/s (from the control table)."""
        return self.model.baudrate_bps(self.table.get("baudrate"))

    @property
    def return_delay_s(self) -> float:
        """Return delay time: the register counts 2 µs per unit (e-manual)."""
        return self.table.get("return_delay_time") * 2e-6

    @property
    def status_return_level(self) -> int:
        """0: answer PING only; 1: PING and READ; 2: every instruction (e-manual)."""
        return self.table.get("status_return_level", 2)

    @property
    def torque_enabled(self) -> bool:
        """True when the torque is on (the motor holds its goal)."""
        return bool(self.table.get("torque_enable"))

    @property
    def goal_position_deg(self) -> float:
        """Goal position in degrees."""
        return self.table.get_si("goal_position") or 0.0

    @property
    def present_position_deg(self) -> float:
        """Present position in degrees."""
        return self.table.get_si("present_position") or 0.0

    @property
    def speed_limit_dps(self) -> float:
        """Speed the motor moves at toward its goal: moving speed, 0 meaning no-load speed."""
        limit = self.model.no_load_speed_dps
        raw = self.table.get("moving_speed")
        speed = abs(self.table.get_si("moving_speed") or 0.0)
        if raw == 0 or speed == 0.0:
            return limit
        return min(speed, limit)

    def position_limits_deg(self) -> tuple[float, float]:
        """Angle limits the goal is kept within (the whole range when the model has none)."""
        half = self.model.position_range_deg / 2
        low = self.table.get_si("min_position_limit")
        high = self.table.get_si("max_position_limit")
        if low is None or high is None or low >= high:
            return -half, half
        return low, high

    def set_state(
        self, position_deg: float, speed_dps: float, load_pct: float, moving: bool
    ) -> None:
        """Set the sensed values (a plant calls this after each step)."""
        with self.lock:
            table = self.table
            table.set_si("present_position", position_deg)
            table.set_si("present_speed", speed_dps)
            table.set_si("present_load", load_pct)
            table.set("moving", int(moving))

    def move_by_hand(self, position_deg: float) -> None:
        """Move the horn by hand: a compliant motor stays there, a stiff one returns to its goal.

        Args:
            position_deg: where the horn is put, in degrees.
        """
        with self.lock:
            if self.hand_mover is not None:
                self.hand_mover(self, position_deg)
            else:
                self.table.set_si("present_position", position_deg)

    def hold_by_hand(self, position_deg: float | None, speed_dps: float = 0.0) -> None:
        """A hand holds the horn at ``position_deg``, moving at ``speed_dps``, until it lets go
        (None).

        Unlike :meth:`move_by_hand` (a horn put somewhere once), the hand stays: a compliant
        motor follows it, a stiff one resists it (its load rises, see ``IdealPlant``). A plant
        that owns the joint state (``hand_mover``) is moved for a compliant motor only.
        """
        with self.lock:
            self.hand_deg = position_deg
            self.hand_speed_dps = speed_dps if position_deg is not None else 0.0
            mover = None if self.torque_enabled else self.hand_mover
            if position_deg is not None and mover is not None:
                mover(self, position_deg)

    @property
    def torque_limit_pct(self) -> float:
        """The torque limit in percent of the maximum (100 for models without one)."""
        limit = self.table.get_si("torque_limit") if self.model.has_torque_limit else None
        return 100.0 if limit is None else float(limit)

    # ------------------------------------------------------------------ faults

    def fail_with(self, errors: int | Iterable[str]) -> None:
        """Raise hardware errors (e.g. ``["overload"]``) as if the motor detected them.

        Protocol 1 sets the named bits in every status error byte; protocol 2 sets the
        hardware error status register and the alert bit (0x80). When the model's shutdown
        register selects the error, the torque goes off, as on hardware (e-manual: Shutdown).

        Args:
            errors: a raw bit mask, or error names (protocol 1: ``input voltage, angle limit,
                overheating, range, checksum, overload, instruction``; protocol 2: ``input
                voltage, overheating, motor encoder, electrical shock, overload``).

        Raises:
            ValueError: an error name the model does not have.
        """
        bits = errors if isinstance(errors, int) else fault_bits(self.model, errors)
        with self.lock:
            self._fault_bits |= bits
            self.table.set("hardware_error_status", self._fault_bits)
            for name in shutdown_register_names():
                if self.table.find(name) is not None and self.table.get(name) & bits:
                    self.table.set("torque_enable", 0)

    def clear_faults(self) -> None:
        """Remove every error raised by :meth:`fail_with`."""
        with self.lock:
            self._fault_bits = 0
            self.table.set("hardware_error_status", 0)

    @property
    def fault_bits(self) -> int:
        """The hardware error bits currently raised."""
        return self._fault_bits

    def error_byte(self, code: int = 0) -> int:
        """Status error byte for an instruction result ``code`` plus the hardware errors."""
        return self.proto.error_byte(code, self._fault_bits)

    # ------------------------------------------------------------------ instruction handling

    def answers(self, instruction: int, broadcast: bool) -> bool:
        """Whether a status packet is returned for ``instruction`` (status return level)."""
        if instruction == Instruction.PING:
            return not broadcast or self.proto.has_broadcast_ping
        if broadcast:
            return False
        level = self.status_return_level
        return level >= 2 or (level >= 1 and instruction == Instruction.READ)

    def status(
        self, code: int = 0, params: bytes = b"", motor_id: int | None = None
    ) -> StatusPacket:
        """A status packet from this motor (``motor_id`` overrides the id, e.g. the old one)."""
        sender = self.id if motor_id is None else motor_id
        return StatusPacket(sender, self.error_byte(code), params)

    def checksum_error(self, instruction: int) -> StatusPacket | None:
        """The reply to a packet addressed to this motor that failed its checksum/CRC."""
        if not self.answers(instruction, broadcast=False):
            return None
        return self.status(self.table.codes.checksum)

    def handle(self, packet: InstructionPacket) -> StatusPacket | None:
        """Execute an instruction addressed to this motor (or broadcast).

        Args:
            packet: PING, READ, WRITE, REG_WRITE, ACTION, FACTORY_RESET, REBOOT or CLEAR.

        Returns:
            The status packet to send back (from the id the motor had when the packet
            arrived), or None when the motor stays silent.
        """
        with self.lock:
            old_id = self.id
            broadcast = packet.id == BROADCAST_ID
            # Like the id and baud rate, the status return level in force is the one the
            # packet arrived under (a write changing it is still answered the old way).
            answers = self.answers(packet.instruction, broadcast)
            try:
                code, params = self._execute(packet, broadcast)
            except ProtocolError as exc:
                logger.debug("motor %d: bad parameters (%s)", old_id, exc)
                code, params = self.table.codes.instruction, b""
            if code < 0 or not answers:
                return None
            return self.status(code, params, motor_id=old_id)

    def _execute(self, packet: InstructionPacket, broadcast: bool) -> tuple[int, bytes]:
        """Run one instruction; returns (result code, reply params), code -1 for silence."""
        ins, params, codes = packet.instruction, packet.params, self.table.codes
        if ins == Instruction.PING:
            firmware = self.table.get("firmware")
            return 0, self.proto.ping_reply(self.table.get("model_number"), firmware)
        if ins == Instruction.READ:
            address, length = parse_read(self.proto, params)
            return self.read_block(address, length)
        if ins in (Instruction.WRITE, Instruction.REG_WRITE):
            address, data = parse_write(self.proto, params)
            code = self.check_write(address, data)
            if code == 0 and ins == Instruction.WRITE:
                self.apply_write(address, data)
            elif code == 0:
                self._registered = (address, data)
                self.table.set("registered", 1)
            return code, b""
        if ins == Instruction.ACTION:
            if self._registered is None:
                return codes.instruction, b""
            address, data = self._registered
            self._registered = None
            self.table.set("registered", 0)
            self.apply_write(address, data)
            return 0, b""
        if ins == Instruction.FACTORY_RESET:
            return self._factory_reset(self.proto.parse_factory_reset(params), broadcast)
        if self.proto.has_reboot and ins == Instruction.REBOOT:
            self._reboot()
            return 0, b""
        if self.proto.has_clear and ins == Instruction.CLEAR:
            parse_clear(params)
            return self._clear_multi_turn(), b""
        return codes.instruction, b""

    # ------------------------------------------------------------------ table access

    def read_block(self, address: int, length: int) -> tuple[int, bytes]:
        """(result code, data) of reading ``length`` bytes at ``address``."""
        with self.lock:
            code = self.table.check_read(address, length)
            if code:
                return code, b""
            return 0, self.table.read(address, length)

    def check_write(self, address: int, data: bytes) -> int:
        """Result code the firmware gives a write (0: accepted); see ``ControlTable``."""
        table = self.table
        code = table.check_write(address, data, torque_on=self.torque_enabled)
        if code:
            return code
        # e-manual (AX-12A/MX-28, Lock (47)): once set, the EEPROM area cannot be written
        # until power is cycled.
        touched = table.touched(address, len(data))
        if table.get("lock") and any(register.memory == "EEPROM" for register in touched):
            return table.codes.access
        goal = table.pending_value("goal_position", address, data)
        if goal is not None and self._limits_apply():
            low, high = table.get("min_position_limit"), table.get("max_position_limit")
            if not low <= goal <= high:
                return table.codes.limit
        return 0

    def _limits_apply(self) -> bool:
        """Whether goal positions are checked against the angle limits (joint/position mode)."""
        table = self.table
        if table.find("operating_mode") is not None:
            return table.get("operating_mode") == 3  # e-manual X-series: 3 = position control
        if table.find("control_mode") is not None:
            return table.get("control_mode") == 2  # e-manual XL-320: 2 = joint mode
        low, high = table.get("min_position_limit"), table.get("max_position_limit")
        return not (low == 0 and high == 0)  # e-manual AX/MX: both limits 0 = wheel mode

    def write_block(self, address: int, data: bytes) -> int:
        """Check then apply a write (sync/bulk write); returns the result code."""
        with self.lock:
            code = self.check_write(address, data)
            if code == 0:
                self.apply_write(address, data)
            return code

    def apply_write(self, address: int, data: bytes) -> None:
        """Store accepted data in the control table."""
        self.table.write(address, data)

    # ------------------------------------------------------------------ resets

    def _factory_reset(self, option: int, broadcast: bool) -> tuple[int, bytes]:
        # e-manual (X-series, Factory Reset): a broadcast "reset all" is not executed.
        if self.proto.refuses_broadcast_reset_all and broadcast and option == _RESET_ALL:
            return -1, b""
        keep_id = option in (_RESET_KEEP_ID, _RESET_KEEP_ID_BAUD)
        keep_baud = option == _RESET_KEEP_ID_BAUD
        motor_id, baud = self.table.get("id"), self.table.get("baudrate")
        position = self.table.get("present_position")
        firmware = self.table.get("firmware")
        self.table.data[:] = self.model.default_table()
        self.table.set("firmware", firmware)
        self.table.set("present_position", position)
        if keep_id:
            self.table.set("id", motor_id)
        if keep_baud:
            self.table.set("baudrate", baud)
        self._registered = None
        self._power_on_sensors()
        return 0, b""

    def _reboot(self) -> None:
        """RAM registers back to their power-on values, hardware errors cleared."""
        table = self.table
        for register in self.model.registers.values():
            if register.memory == "RAM" and register.writable and register.default is not None:
                table.store(register, register.default)
        table.set("goal_position", table.get("present_position"))
        self._registered = None
        self._fault_bits = 0
        table.set("hardware_error_status", 0)
        table.set("registered", 0)

    def _clear_multi_turn(self) -> int:
        """CLEAR: fold the present position back into one turn (refused while moving)."""
        table = self.table
        if table.get("moving"):
            return 0x01  # e-manual (Protocol 2.0, Clear): Result Fail while the motor moves
        position = table.get("present_position")
        table.set("present_position", position % self.model.resolution)
        return 0
