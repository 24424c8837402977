"""Open the bus where a motor answers: the given baud rate and protocol, or search for it."""

from __future__ import annotations

from contextlib import contextmanager
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Iterator

    from poppy_core.bus.dxlbus import DxlBus
    from poppy_core.bus.results import PingResult


def locate(port: str, ids: list[int], baud: int | None, protocol: int | None) -> tuple[int, int]:
    """Find the (baudrate, protocol) where the first of ``ids`` answers on ``port``.

    1 Mbps is tried first in each protocol, then the other standard rates.

    Raises:
        SetupError: no motor with those IDs answers at any rate tried.
    """
    from poppy_core.bus.scan import scan
    from poppy_core.errors import SetupError
    from poppy_core.models import standard_baudrates

    protocols = [protocol] if protocol else [2, 1]
    for proto in protocols:
        rates = (
            [baud]
            if baud
            else sorted(standard_baudrates(proto), key=lambda r: (r != 1_000_000, -r))
        )
        for rate in rates:
            found = scan(port, [rate], [proto], ids, broadcast=False)
            if found:
                return found[0].baudrate, found[0].protocol
    tried_proto = "protocol " + " and ".join(map(str, protocols))
    tried_rate = f"{baud} bps" if baud else "every standard baud rate"
    id_text = ", ".join(map(str, ids))
    raise SetupError(
        f"no motor with ID {id_text} answers on {port} ({tried_proto}, {tried_rate}): "
        "check power and wiring, or run `poppy scan --all-bauds`"
    )


@contextmanager
def open_bus(port: str, ids: list[int], baud: int | None, protocol: int | None) -> Iterator[DxlBus]:
    """Open a ``DxlBus`` where ``ids`` answer (searching when baud or protocol is unknown)."""
    from poppy_core.bus.dxlbus import DxlBus

    if baud is None or protocol is None:
        baud, protocol = locate(port, ids, baud, protocol)
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
