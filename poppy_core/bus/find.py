"""``find_bus``: the open bus where given motors all answer (``find_port``: its address)."""

from __future__ import annotations

import logging
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from poppy_core.bus.dxlbus import DxlBus
from poppy_core.bus.ports import list_ports
from poppy_core.bus.settle import answers, ping_found, settle
from poppy_core.bus.timing import MIN_REPLY_TIMEOUT_S
from poppy_core.bus.transport import Transport, open_each
from poppy_core.errors import PortError, SetupError
from poppy_core.models import standard_baudrates

logger = logging.getLogger(__name__)

DEFAULT_SEARCH_FIRST_BPS = 1_000_000
FACTORY_BPS = 57_600
"""The factory rate of MX and X-series motors: searched second, so a new motor is found early."""
PROTOCOLS = (1, 2)
PATIENT_LATENCY_S = 0.15
"""The adapter latency assumed by the last, patient look of a search (``find_bus``) or a scan
(``scan``) that found nothing (``patient_steps``): a machine too busy to run the motors' replies
on time (a loaded Pi, an emulator under load) is then found at the common rates, for a few
seconds more before a search that must fail."""
PATIENT_RATES = 1
"""How many of the first rates of the plan a scan's patient look tries again: 1 Mbps, the rate
of Poppy robots (each rate more costs a scan's pass over every ID again)."""
SEARCH_PATIENT_RATES = 2
"""How many a search's patient look (``find_bus``) tries again: 1 Mbps and 57,600 bps, the
factory rate of MX and X-series motors (a search asks only its few IDs: each rate costs about
a second more before a search that must fail)."""


def _answering(bus: DxlBus, wanted: list[int]) -> tuple[list[int], set[int]]:
    """Which of ``wanted`` answer at the bus's rate, confirmed on a settled line (as in scan).

    Returns:
        The IDs confirmed, and the IDs heard but not confirmed (late replies from elsewhere).
    """
    heard = {i for i in wanted if ping_found(bus, i, retries=1) is not None}
    heard |= settle(bus) & set(wanted)
    confirmed = [i for i in wanted if i in heard and answers(bus, i)]
    return confirmed, heard - set(confirmed)


@dataclass
class _Closest:
    """The best partial answer of a search, for its error message."""

    count: int = 0
    text: str = ""

    def offer(self, bus: DxlBus, answered: list[int]) -> None:
        if len(answered) > self.count:
            self.count = len(answered)
            self.text = (
                f"{bus.port} at {bus.baudrate} bps, protocol {bus.protocol} "
                f"has {', '.join(map(str, answered))}"
            )


def search_order(protocols: list[int], fixed: list[int] | None) -> list[tuple[int, list[int]]]:
    """The rates to try, each with the protocols to try at it: 1 Mbps first, then 57,600 bps.

    1 Mbps is the rate of Poppy robots and of most set-up buses, so the common case is found
    at the first rate, whichever its protocol; 57,600 bps is the factory rate of MX and
    X-series motors; then each protocol's standard rates in order.
    """
    order: dict[int, list[int]] = {}
    for protocol in protocols:
        for rate in fixed if fixed is not None else standard_baudrates(protocol):
            order.setdefault(rate, []).append(protocol)
    first = (DEFAULT_SEARCH_FIRST_BPS, FACTORY_BPS)
    return sorted(order.items(), key=lambda item: first.index(item[0]) if item[0] in first else 2)


def patient_steps(
    plan: list[tuple[int, list[int]]], learned_s: float | None, rates: int = PATIENT_RATES
) -> list[tuple[int, int, float]]:
    """The last, patient look of a search where nothing at all answered (``find_bus``, ``scan``).

    Args:
        plan: the search's rates, each with its protocols, first rates first (``search_order``).
        learned_s: the adapter latency learned by the search (None: nothing learned).
        rates: how many of the plan's first rates to try again.

    Returns:
        ``(rate, protocol, latency_s)`` to try again: the first ``rates`` rates of the plan, in
        each of their protocols, with a latency of ``PATIENT_LATENCY_S`` at least, so that
        replies a busy machine made late are not taken for an empty bus.
    """
    patient_s = max(learned_s or 0.0, PATIENT_LATENCY_S)
    return [(rate, p, patient_s) for rate, protocols in plan[:rates] for p in protocols]


def _search_bus(
    port: str, rate: int, protocol: int, transport: Transport, latency_s: float | None
) -> DxlBus:
    """A search's bus at one rate: the adapter's own floor, whatever ``$POPPY_REPLY_FLOOR_S``
    says (a search mostly asks rates where nobody answers; late replies have their own steps)."""
    bus = DxlBus(
        port,
        rate,
        protocol,
        latency_s=latency_s,
        transport=transport,
        min_timeout_s=MIN_REPLY_TIMEOUT_S,
    )
    bus.adaptive_latency = True
    return bus


def _search(
    port: str,
    transport: Transport,
    wanted: list[int],
    plan: list[tuple[int, list[int]]],
    latency_s: float | None,
    closest: _Closest,
) -> DxlBus | None:
    """Try ``plan`` on one open port; the bus (not owning ``transport``) where all answer."""
    learned = latency_s
    previous: dict[int, int] = {}  # per protocol, the rate tried before (see scan._revisit)
    for rate, protocols in plan:
        for protocol in protocols:
            bus = _search_bus(port, rate, protocol, transport, learned)
            answered, heard_late = _answering(bus, wanted)
            learned = bus.latency_s
            if len(answered) == len(wanted):
                return bus
            earlier = previous.get(protocol)
            if heard_late and earlier is not None:
                again = _search_bus(port, earlier, protocol, transport, learned)
                if len(_answering(again, wanted)[0]) == len(wanted):
                    return again
            previous[protocol] = rate
            closest.offer(bus, answered)
    if closest.count:  # some motors answered in time: the others are absent, not late
        return None
    for rate, protocol, patient_s in patient_steps(plan, learned, SEARCH_PATIENT_RATES):
        bus = _search_bus(port, rate, protocol, transport, patient_s)
        if len(_answering(bus, wanted)[0]) == len(wanted):
            return bus
    return None


def find_bus(
    ids: Iterable[int],
    ports: Sequence[str] | None = None,
    baudrates: Iterable[int] | None = None,
    protocols: Iterable[int] = PROTOCOLS,
    *,
    latency_s: float | None = None,
) -> DxlBus:
    """Open the bus holding every motor in ``ids``: each port is opened once and searched.

    Args:
        ids: motor IDs that must all answer.
        ports: ports to try; None tries every port ``list_ports`` finds.
        baudrates: rates to try; None tries the standard rates of each protocol.
        protocols: protocols to try.
        latency_s: adapter latency (None: from the port).

    Returns:
        The open ``DxlBus`` at the rate and protocol found (the caller closes it; it is a
        context manager). Rates are tried in the outer loop, 1 Mbps first, and the protocols
        at each rate in the inner one, so a Poppy robot is found at the first rate tried.

    A motor that answers is asked again once the line has settled, so that a late reply (a
    slow adapter) is not taken for a motor at the next rate tried; a slower adapter than
    assumed is learned from its replies (see ``poppy_core.bus.latency``). When nothing at all
    answered, 1 Mbps and 57,600 bps are tried once more with a patient wait
    (``PATIENT_LATENCY_S``): replies a busy machine made late are not taken for an empty bus.

    Raises:
        PortError: no serial port at all; the only port given (or every one) cannot be opened.
        SetupError: no port/rate/protocol answers for every ID (the message says the closest).
    """
    wanted = list(ids)
    protocols = list(protocols)
    fixed = None if baudrates is None else list(baudrates)
    plan = search_order(protocols, fixed)
    port_list = list(ports) if ports is not None else [p.device for p in list_ports()]
    if not port_list:
        raise PortError("no serial port found: plug the adapter or run `poppy ports`")
    closest = _Closest()
    unopened: list[PortError] = []
    for port, transport in open_each(port_list, unopened):
        found = None
        try:
            found = _search(port, transport, wanted, plan, latency_s, closest)
        finally:
            if found is None:
                transport.close()
        if found is not None:
            bus = DxlBus(
                port, found.baudrate, found.protocol, latency_s=found.latency_s, transport=transport
            )
            bus.adopt_transport()
            return bus
    if len(unopened) == len(port_list):
        reasons = "; ".join(str(exc) for exc in unopened)
        raise PortError(f"no port could be opened: {reasons}")
    nearest = f"; closest: {closest.text}" if closest.count else ""
    rates_text = "every standard rate" if fixed is None else ", ".join(f"{r} bps" for r in fixed)
    protocols_text = " and ".join(str(p) for p in protocols)
    raise SetupError(
        f"no motor {', '.join(map(str, wanted))} answers (searched {', '.join(port_list)} at "
        f"{rates_text}, protocol {protocols_text}){nearest}: check power and wiring, "
        "or run `poppy scan --all-bauds`"
    )


def find_port(
    ids: Iterable[int],
    ports: Sequence[str] | None = None,
    baudrates: Iterable[int] | None = None,
    protocols: Iterable[int] = PROTOCOLS,
    *,
    latency_s: float | None = None,
) -> tuple[str, int, int]:
    """Find the bus holding every motor in ``ids`` (see ``find_bus``, which keeps it open).

    Returns:
        ``(port, baudrate, protocol)``.

    Raises:
        PortError: no serial port at all; the only port given (or every one) cannot be opened.
        SetupError: no port/rate/protocol answers for every ID (the message says the closest).
    """
    with find_bus(ids, ports, baudrates, protocols, latency_s=latency_s) as bus:
        return bus.port, bus.baudrate, bus.protocol
