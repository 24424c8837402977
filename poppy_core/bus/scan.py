"""Motor discovery: scan ports, baud rates and protocols; find the port holding given motors.

How a scan stays fast:

* every ping waits only for the physical round trip (first status byte), not a flat timeout;
* a reply is trusted as soon as its checksum/CRC is valid, so found motors are not re-pinged;
  a reply that arrives late (after its own deadline) is still caught: it shows up as a stray
  packet during the next ping, and that ID is pinged again at the end of the pass;
* protocol 2 first sends a broadcast ping, which finds every motor at that rate in a single
  transaction, twice. The result is trusted when both found the same motors and the line stayed
  clean (no corrupt packet and no stray byte): then the per-ID pings at that rate are skipped,
  silence included. Two broadcasts that disagree (a reply late because the OS ran us late,
  replies colliding, noise) mean one may have missed someone, so every ID is pinged one by one.
  The second broadcast costs one round trip, a few ms at 1 Mbps.
* two broadcasts that both heard nothing agree too, and may only mean that the other end was
  run late past both deadlines (an emulator on a busy machine: every motor was hidden from
  ``poppy scan`` in 1 run of 5). So an empty pair is believed only once nothing came in the
  ``silence_s`` after the second broadcast (50 ms; 10 adapter latencies on a slower adapter),
  longer than the OS runs a process late on a loaded machine. The quiet time before the next
  rate cannot stand in for it: it is short (``settle_s``), and switching rates drops what was
  not read yet. Replies heard meanwhile, late ones kept aside during the second broadcast
  included, are asked again; if the motor is still late, its late broadcast reply stands for
  it. A rate where nobody answers costs about 45 ms more (the 17-rate sweep, with 7 empty
  protocol 2 rates, 0.36 s more: 2.7 %); a rate where motors answered pays nothing.

Slow adapters: the deadlines assume the adapter latency known for the port (see
``poppy_core.bus.timing``); a reply that came after its deadline raises it for the rest of the
port's scan (``poppy_core.bus.latency``). The pass that pings each ID keeps the port's deadline,
though: a silent ID costs no more than it did, and on an adapter that answers on time a
reply the OS made late once costs one more ping, not a longer wait at every ID still to ping; a
slow adapter's replies, late, are caught as strays and their IDs pinged again after the pass,
with the latency learned. Before motors found at a rate are reported, the line is left quiet for
a few latencies and they are asked again: a reply that came late from the rate tried before (and
was taken for an answer at this one) does not answer twice, and is dropped. At the first rate
tried on a port there is no rate before, and nothing to ask again.

When nothing at all answered on a port, its first rates are scanned once more with a patient
wait (``find.patient_steps``, as ``find_bus`` looks: 1 Mbps, 0.15 s a reply), so that replies a
busy machine made late are not taken for an empty bus. Its pass over every ID keeps the port's
deadline (late replies come as strays, asked again patiently); an empty bus at 1 Mbps, both
protocols, costs about 3 s more (1.1 s before).

A scan opens each port once and switches rates on it. On an abort (``should_abort()`` true) it
returns what it has found so far.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Sequence

from poppy_core.bus.dxlbus import DxlBus
from poppy_core.bus.find import (
    DEFAULT_SEARCH_FIRST_BPS,
    PROTOCOLS,
    find_bus,
    find_port,
    patient_steps,
    search_order,
)
from poppy_core.bus.results import FoundMotor, PingResult, ScanProgress
from poppy_core.bus.scan_state import ScanState, found_motor
from poppy_core.bus.settle import (
    answers,
    ask_patiently,
    doubt_learned,
    heard_in_silence,
    ping_found,
    settle,
)
from poppy_core.bus.timing import DEFAULT_RETURN_DELAY_S, LinkTiming
from poppy_core.bus.transport import Transport, open_each
from poppy_core.models import standard_baudrates

__all__ = [
    "DEFAULT_SEARCH_FIRST_BPS",
    "PROTOCOLS",
    "SCAN_IDS",
    "answers",
    "find_bus",
    "find_port",
    "scan",
    "settle",
]

logger = logging.getLogger(__name__)

SCAN_IDS = range(254)


def _scan_rate(
    state: ScanState,
    port: str,
    bus: DxlBus,
    broadcast: bool,
    *,
    first: bool = False,
    last: bool = False,
    pass_latency_s: float | None = None,
) -> set[int]:
    """Scan one (port, rate, protocol); motors answering are confirmed before being reported.

    ``first``: nothing was sent on the port before in this scan, so no late reply from another
    rate can be taken for a motor here: the motors found are reported without asking again.
    ``last``: no rate comes after on this port; after a trusted broadcast ping no reply is
    still coming, and the line need not be left quiet. ``pass_latency_s``: the latency the
    pass over every ID assumes (the port's, not one learned since; None: the bus's).

    Returns:
        IDs heard at this rate that did not confirm: late replies from the rate before.
    """
    candidates: dict[int, PingResult] = {}
    wanted = set(state.ids)
    trusted = False
    began_s = bus.latency_s
    if bus.proto.has_broadcast_ping and broadcast:
        transport = bus.transport
        corrupt, skipped = transport.corrupt_packets, transport.skipped_bytes
        answered: list[set[int]] = []
        for _ in range(2):
            results = bus.broadcast_ping()
            answered.append({pinged.id for pinged in results})
            for pinged in results:
                if pinged.id in wanted:
                    candidates.setdefault(pinged.id, pinged)
        clean = transport.corrupt_packets == corrupt and transport.skipped_bytes == skipped
        trusted = clean and answered[0] == answered[1]
        state.unconfirmed = len(candidates)
        if trusted:
            state.report(port, bus, "broadcast ping", None, len(state.ids))
        else:
            logger.info(
                "%s: broadcast pings at %d bps disagree or met garbage; pinging each ID",
                port,
                bus.baudrate,
            )
    late: set[int] = set()
    heard: dict[int, PingResult] = {}
    if trusted and not candidates:  # silence may be lateness (module docstring)
        heard = heard_in_silence(bus, wanted)
        late.update(heard)
    if not trusted:
        late.update(s.id for s in bus.take_strays() if s.id in wanted)  # late broadcast replies
        # The pass keeps the port's deadline, whatever is learned (module docstring).
        bus.timeout_s = _ping_deadline_s(bus, pass_latency_s or bus.latency_s)
        try:
            for motor_id in state.ids:
                if state.abort_requested():
                    break
                if motor_id not in candidates:
                    result = ping_found(bus, motor_id, retries=0)
                    if result is not None:
                        candidates[motor_id] = result
                        state.unconfirmed = len(candidates)
                    strays = bus.take_strays()
                    late.update(s.id for s in strays if s.id in wanted and s.id not in candidates)
                state.report(port, bus, "ping", motor_id, 1)
        finally:
            bus.timeout_s = None
    if bus.latency_s > began_s and candidates:  # before the waits that follow use it
        late |= doubt_learned(bus, began_s, max(candidates)) & wanted
    # Replies still coming are late answers of this rate: wait for them before the next rate.
    if not (trusted and last):
        late |= settle(bus) & wanted
    _ask_the_late(bus, late, candidates, heard, wanted)
    unconfirmed = _report(state, port, bus, candidates, first=first, by_broadcast=trusted)
    here = _found_here(state, bus)
    if bus.latency_s > began_s and here:
        came = (doubt_learned(bus, began_s, max(here)) & wanted) - here
        if came:  # late replies heard while doubting: asked too (one came behind another so)
            more: dict[int, PingResult] = {}
            _ask_the_late(bus, came, more, {}, wanted)
            late |= came
            unconfirmed |= _report(state, port, bus, more, first=first, by_broadcast=False)
            here = _found_here(state, bus)
    return (unconfirmed | late) - here


def _report(
    state: ScanState,
    port: str,
    bus: DxlBus,
    candidates: dict[int, PingResult],
    *,
    first: bool,
    by_broadcast: bool,
) -> set[int]:
    """Report ``candidates``: at once at the port's first rate, else once confirmed.

    Returns:
        The candidates that did not confirm.
    """
    if not first:
        return _confirm(state, port, bus, candidates, by_broadcast=by_broadcast)
    for result in candidates.values():
        state.add(found_motor(port, bus, result))
    state.unconfirmed = 0
    return set()


def _found_here(state: ScanState, bus: DxlBus) -> set[int]:
    """The IDs found so far at ``bus``'s rate and protocol."""
    return {f.id for f in state.found if (f.baudrate, f.protocol) == (bus.baudrate, bus.protocol)}


def _ask_the_late(
    bus: DxlBus,
    late: set[int],
    candidates: dict[int, PingResult],
    heard: dict[int, PingResult],
    wanted: set[int],
) -> None:
    """Ask each ID whose reply came late (``late``) again; those found join ``candidates``.

    A late broadcast reply stands for its motor if asking again goes unanswered (the other end
    still late); a motor still silent is asked patiently (``ask_patiently``). Replies that come
    late while these are asked (kept aside, or heard in a quiet time) are asked in turn, and
    added to ``late``: a reply held back behind another was lost so once.
    """
    pending = sorted(late - set(candidates))
    asked: set[int] = set()
    while pending:
        motor_id = pending.pop(0)
        asked.add(motor_id)
        came: set[int] = set()
        result = (
            ping_found(bus, motor_id, retries=1)
            or heard.get(motor_id)
            or ask_patiently(bus, motor_id, heard=came)
        )
        if result is not None:
            candidates[motor_id] = result
        came |= {status.id for status in bus.take_strays()}
        for other in sorted((came & wanted) - set(candidates) - asked - set(pending)):
            pending.append(other)
            late.add(other)


def _ping_deadline_s(bus: DxlBus, latency_s: float) -> float:
    """How long a ping waits at ``bus``'s rate with an adapter latency of ``latency_s``."""
    proto = bus.proto
    tx, rx = proto.instruction_size(0), proto.status_size(proto.ping_params)
    timing = LinkTiming(bus.baudrate, bus.timing.return_delay_s, latency_s)
    return timing.reply_timeout_s(tx, rx)


def _scan_bus(
    port: str,
    rate: int,
    protocol: int,
    transport: Transport,
    latency_s: float | None,
    return_delay_s: float,
) -> DxlBus:
    """A scan's bus at one rate: no retry, no floor, learning the adapter's latency."""
    bus = DxlBus(
        port,
        rate,
        protocol,
        latency_s=latency_s,
        retries=0,
        return_delay_s=return_delay_s,
        transport=transport,
        min_timeout_s=0.0,
    )
    bus.adaptive_latency = True
    return bus


def _revisit(state: ScanState, port: str, bus: DxlBus, ids: set[int]) -> None:
    """Look again at the rate before for motors whose replies came late into the next one.

    ``bus`` is at that earlier rate, with the latency learned since; a motor found there is
    confirmed as usual.
    """
    known = {(f.id, f.baudrate, f.protocol) for f in state.found}
    ids = {i for i in ids if (i, bus.baudrate, bus.protocol) not in known}
    if not ids:
        return
    logger.info(
        "%s: replies from %s came late into the next rate: looking again at %d bps",
        port,
        ", ".join(map(str, sorted(ids))),
        bus.baudrate,
    )
    settle(bus)
    candidates = {}
    for motor_id in sorted(ids):
        result = ping_found(bus, motor_id, retries=1) or ask_patiently(bus, motor_id)
        if result is not None:
            candidates[motor_id] = result
    _confirm(state, port, bus, candidates, by_broadcast=False)


def _confirm(
    state: ScanState, port: str, bus: DxlBus, candidates: dict[int, PingResult], by_broadcast: bool
) -> set[int]:
    """Report the candidates that answer again, now that the line has settled.

    On a slow adapter a reply can come after the settle time, while the next rate is tried: it
    would be taken for a motor at that rate. A motor really at this rate answers again; a late
    reply from elsewhere does not.

    Returns:
        The candidates that did not answer again.
    """
    state.unconfirmed = 0
    if not candidates:
        return set()
    again: set[int] = set()
    if by_broadcast:
        again = {pinged.id for pinged in bus.broadcast_ping()}
    again |= {i for i in candidates if i not in again and answers(bus, i)}
    again |= {i for i in candidates if i not in again and ask_patiently(bus, i, identify=False)}
    for motor_id, result in candidates.items():
        if motor_id in again:
            state.add(found_motor(port, bus, result))
        else:
            logger.info(
                "%s: motor %d answered once at %d bps but not when asked again: a late reply "
                "from another rate, not counted",
                port,
                motor_id,
                bus.baudrate,
            )
    return set(candidates) - again


def _patient_look(
    state: ScanState,
    port: str,
    transport: Transport,
    plan: list[tuple[int, list[int]]],
    timing: tuple[float | None, float],
    broadcast: bool,
    pass_latency_s: float | None,
) -> None:
    """Nothing answered on ``port``: its first rates once more, with a patient wait.

    ``find.patient_steps`` says which rates and how patient (``find_bus`` looks the same way);
    ``timing`` is the latency learned and the return delay. The pass over every ID keeps the
    port's deadline (``pass_latency_s``): its late replies are caught as strays and asked again
    with the patient wait, so a silent ID costs no more than before.
    """
    steps = patient_steps(plan, timing[0])
    if steps:
        logger.info("%s: nothing answered: looking again, patient (a busy machine?)", port)
    state.total += len(steps) * len(state.ids)
    for rate, protocol, patient_s in steps:
        if state.abort_requested():
            return
        bus = _scan_bus(port, rate, protocol, transport, patient_s, timing[1])
        last = (rate, protocol) == steps[-1][:2]
        _scan_rate(state, port, bus, broadcast, last=last, pass_latency_s=pass_latency_s)


def scan(
    ports: str | Sequence[str],
    baudrates: Iterable[int] | None = None,
    protocols: Iterable[int] = PROTOCOLS,
    ids: Iterable[int] = SCAN_IDS,
    *,
    progress: Callable[[ScanProgress], None] | None = None,
    should_abort: Callable[[], bool] | None = None,
    on_found: Callable[[FoundMotor], None] | None = None,
    broadcast: bool = True,
    latency_s: float | None = None,
    return_delay_s: float = DEFAULT_RETURN_DELAY_S,
    patient: bool = True,
) -> list[FoundMotor]:
    """Find every motor answering on ``ports`` at ``baudrates`` in ``protocols``.

    Args:
        ports: one port or several (device paths or URLs).
        baudrates: rates to try; None tries the standard rates of each protocol.
        protocols: protocols to try (1, 2 or both).
        ids: IDs to look for (0-253).
        progress: called after each ping (and after a trusted broadcast ping).
        should_abort: polled before each ping; when it returns True the scan stops and returns
            what it found.
        on_found: called for each motor as soon as it is found.
        broadcast: use a protocol 2 broadcast ping first (see the module docstring).
        latency_s: adapter latency (None: from the port).
        return_delay_s: return delay assumed in timeouts.
        patient: look again patiently at a port where nothing answered (False: a caller
            trying rates one by one, whose first call was patient, pays it once).

    Returns:
        The motors found, in the order found. Unknown model numbers give ``model=None``. A
        port where nothing answered was looked at again, patiently (module docstring).

    Raises:
        PortError: the only port given cannot be opened (with several ports, one that cannot
            be opened is logged and skipped).
    """
    port_list = [ports] if isinstance(ports, str) else list(ports)
    protocol_list = list(protocols)
    fixed = None if baudrates is None else list(baudrates)
    rates = {p: fixed if fixed is not None else list(standard_baudrates(p)) for p in protocol_list}
    id_list = list(ids)
    total = len(port_list) * sum(len(rates[p]) for p in protocol_list) * len(id_list)
    state = ScanState(id_list, progress, should_abort, on_found, total)
    for port, transport in open_each(port_list):
        learned = latency_s  # a slower adapter than assumed is learned once, for every rate
        first = True  # nothing sent on this port yet: nothing can come late from elsewhere
        assumed: float | None = None  # the port's latency, before anything is learned
        try:
            for protocol in protocol_list:
                previous: int | None = None
                for rate in rates[protocol]:
                    if state.abort_requested():
                        return state.found

                    timing = (learned, return_delay_s)
                    bus = _scan_bus(port, rate, protocol, transport, *timing)
                    last = protocol == protocol_list[-1] and rate == rates[protocol][-1]
                    assumed = bus.latency_s if assumed is None else assumed
                    heard_late = _scan_rate(
                        state, port, bus, broadcast, first=first, last=last, pass_latency_s=assumed
                    )
                    first = False
                    learned = bus.latency_s
                    if heard_late and previous is not None:
                        earlier = _scan_bus(port, previous, protocol, transport, learned, timing[1])
                        _revisit(state, port, earlier, heard_late)
                    previous = rate
            if patient and not state.aborted and not any(f.port == port for f in state.found):
                plan = search_order(protocol_list, fixed)
                timing = (learned, return_delay_s)
                _patient_look(state, port, transport, plan, timing, broadcast, assumed)
        finally:
            transport.close()
    return state.found
