"""``find_port``: the port, baud rate and protocol where given motors all answer."""

from __future__ import annotations

import logging
from collections.abc import Iterable, Sequence

from poppy_core.bus.dxlbus import DxlBus
from poppy_core.bus.ports import list_ports
from poppy_core.bus.settle import answers, ping_found, settle
from poppy_core.bus.transport import Transport
from poppy_core.errors import PortError, SetupError
from poppy_core.models import standard_baudrates

logger = logging.getLogger(__name__)

DEFAULT_SEARCH_FIRST_BPS = 1_000_000
PROTOCOLS = (1, 2)


def _answering(bus: DxlBus, wanted: list[int]) -> tuple[list[int], set[int]]:
    """Which of ``wanted`` answer at the bus's rate, confirmed on a settled line (as in scan).

    Returns:
        The IDs confirmed, and the IDs heard but not confirmed (late replies from elsewhere).
    """
    heard = {i for i in wanted if ping_found(bus, i, retries=1) is not None}
    heard |= settle(bus) & set(wanted)
    confirmed = [i for i in wanted if i in heard and answers(bus, i)]
    return confirmed, heard - set(confirmed)


def find_port(
    ids: Iterable[int],
    ports: Sequence[str] | None = None,
    baudrates: Iterable[int] | None = None,
    protocols: Iterable[int] = PROTOCOLS,
    *,
    latency_s: float | None = None,
) -> tuple[str, int, int]:
    """Find the bus holding every motor in ``ids``.

    Args:
        ids: motor IDs that must all answer.
        ports: ports to try; None tries every port ``list_ports`` finds.
        baudrates: rates to try; None tries the standard rates of each protocol.
        protocols: protocols to try.
        latency_s: adapter latency (None: from the port).

    Returns:
        ``(port, baudrate, protocol)``.

    A motor that answers is asked again once the line has settled, so that a late reply (a
    slow adapter) is not taken for a motor at the next rate tried; a slower adapter than
    assumed is learned from its replies (see ``poppy_core.bus.latency``).

    Raises:
        PortError: no serial port at all; the only port given (or every one) cannot be opened.
        SetupError: no port/rate/protocol answers for every ID (the message says the closest).
    """
    wanted = list(ids)
    protocols = list(protocols)
    fixed = None if baudrates is None else list(baudrates)
    port_list = list(ports) if ports is not None else [p.device for p in list_ports()]
    if not port_list:
        raise PortError("no serial port found: plug the adapter or run `poppy ports`")
    best: tuple[int, str] = (0, "")
    unopened: list[PortError] = []
    for port in port_list:
        try:
            transport = Transport(port)
        except PortError as exc:
            if len(port_list) == 1:
                raise
            logger.warning("skipping %s: %s", port, exc)
            unopened.append(exc)
            continue
        learned = latency_s
        try:
            for protocol in protocols:
                # 1 Mbps first: the rate of Poppy robots and of most set-up buses
                rates = sorted(
                    fixed if fixed is not None else standard_baudrates(protocol),
                    key=lambda rate: rate != DEFAULT_SEARCH_FIRST_BPS,
                )
                previous: int | None = None
                for rate in rates:
                    bus = DxlBus(port, rate, protocol, latency_s=learned, transport=transport)
                    bus.adaptive_latency = True
                    answered, heard_late = _answering(bus, wanted)
                    learned = bus.latency_s
                    if len(answered) == len(wanted):
                        return port, rate, protocol
                    if heard_late and previous is not None:  # see _revisit
                        earlier = DxlBus(port, previous, protocol, latency_s=learned,
                                         transport=transport)  # fmt: skip
                        earlier.adaptive_latency = True
                        if len(_answering(earlier, wanted)[0]) == len(wanted):
                            return port, previous, protocol
                    previous = rate
                    if len(answered) > best[0]:
                        best = (
                            len(answered),
                            f"{port} at {rate} bps, protocol {protocol} "
                            f"has {', '.join(map(str, answered))}",
                        )
        finally:
            transport.close()
    if len(unopened) == len(port_list):
        reasons = "; ".join(str(exc) for exc in unopened)
        raise PortError(f"no port could be opened: {reasons}")
    closest = f"; closest: {best[1]}" if best[0] else ""
    rates_text = "every standard rate" if fixed is None else ", ".join(f"{r} bps" for r in fixed)
    protocols_text = " and ".join(str(p) for p in protocols)
    raise SetupError(
        f"no motor {', '.join(map(str, wanted))} answers (searched {', '.join(port_list)} at "
        f"{rates_text}, protocol {protocols_text}){closest}: check power and wiring, "
        "or run `poppy scan --all-bauds`"
    )
