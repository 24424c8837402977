"""The state of one scan run (``bus.scan``): IDs looked for, progress, abort, motors found."""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field

from poppy_core.bus.dxlbus import DxlBus
from poppy_core.bus.results import FoundMotor, PingResult, ScanProgress

logger = logging.getLogger(__name__)


def found_motor(port: str, bus: DxlBus, result: PingResult) -> FoundMotor:
    """The motor that answered ``result`` on ``port``, at ``bus``'s rate and protocol."""
    return FoundMotor(
        port=port,
        baudrate=bus.baudrate,
        protocol=bus.protocol,
        id=result.id,
        model_number=result.model_number,
        model=result.model_name,
        firmware=result.firmware,
    )


@dataclass
class ScanState:
    """State of one scan run: IDs looked for, progress, abort, motors found."""

    ids: list[int]
    progress: Callable[[ScanProgress], None] | None
    should_abort: Callable[[], bool] | None
    on_found: Callable[[FoundMotor], None] | None
    total: int
    done: int = 0
    found: list[FoundMotor] = field(default_factory=list)
    unconfirmed: int = 0  # motors that answered at the rate being scanned, not yet confirmed
    aborted: bool = False

    def abort_requested(self) -> bool:
        """Whether the scan must stop (``should_abort`` asked once true, then remembered)."""
        if not self.aborted and self.should_abort is not None and self.should_abort():
            logger.info("scan aborted after %d ping(s)", self.done)
            self.aborted = True
        return self.aborted

    def report(self, port: str, bus: DxlBus, step: str, motor_id: int | None, count: int) -> None:
        """``count`` more steps done (``motor_id`` pinged, None: a broadcast): tell ``progress``."""
        self.done += count
        if self.progress is not None:
            self.progress(
                ScanProgress(
                    port,
                    bus.baudrate,
                    bus.protocol,
                    step,
                    motor_id,
                    self.done,
                    self.total,
                    len(self.found) + self.unconfirmed,
                )
            )

    def add(self, motor: FoundMotor) -> None:
        """Count ``motor`` as found and tell ``on_found``."""
        self.found.append(motor)
        logger.info(
            "found motor %d (%s) on %s at %d bps, protocol %d",
            motor.id,
            motor.model or f"model {motor.model_number}",
            motor.port,
            motor.baudrate,
            motor.protocol,
        )
        if self.on_found is not None:
            self.on_found(motor)
