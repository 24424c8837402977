"""Open the bus where a motor answers: the given baud rate and protocol, or search for it."""

from __future__ import annotations

from contextlib import contextmanager
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Iterator

    from poppy_core.bus.dxlbus import DxlBus
    from poppy_core.bus.results import PingResult


@contextmanager
def open_bus(port: str, ids: list[int], baud: int | None, protocol: int | None) -> Iterator[DxlBus]:
    """Open a ``DxlBus`` where ``ids`` answer (searching when baud or protocol is unknown).

    The port is opened once: a search hands on the bus it found the motors on.
    """
    from poppy_core.bus.dxlbus import DxlBus
    from poppy_core.bus.find import PROTOCOLS, find_bus

    if baud is None or protocol is None:
        rates = None if baud is None else [baud]
        bus = find_bus(ids, [port], rates, PROTOCOLS if protocol is None else [protocol])
    else:
        bus = DxlBus(port, baud, protocol)
    try:
        yield bus
    finally:
        bus.close()


def ping_model(bus: DxlBus, motor_id: int) -> PingResult:
    """Ping ``motor_id`` and return what it is; a clear error when silent or unknown."""
    from poppy_core.errors import SetupError, UnknownModelError

    result = bus.ping(motor_id)
    if result is None:
        raise SetupError(
            f"motor {motor_id} does not answer on {bus.port} at {bus.baudrate} bps "
            f"(protocol {bus.protocol}); run `poppy scan` to see which IDs answer"
        )
    if result.model is None:
        raise UnknownModelError(
            f"motor {motor_id} reports model number {result.model_number}, "
            "which poppy does not know"
        )
    return result
