"""A noisy line: garbled replies are retried at once and in smaller groups, never taken for
silence, and never change how the bus reads."""

from __future__ import annotations

import threading

from poppy_core.bus import DxlBus
from poppy_core.emulator import FaultInjector, build_bus_from_spec, serve_pty
from poppy_core.protocol import StatusPacket, ping
from tests.helpers.bus import loaded_reply_floor_s
from tests.helpers.waiting import eventually

MX_PRESENT = 36  # MX-28 present position (e-manual), 2 bytes
XL_PRESENT = 37  # XL-320 present position (e-manual), 2 bytes
HOUR_S = 3600.0


class GarbleReplies(FaultInjector):
    """Flips a bit in the middle of the replies numbered in ``which`` (1 = the first)."""

    def __init__(self, which: set[int]) -> None:
        super().__init__()
        self.which = which
        self.count = 0

    def filter_reply(self, data: bytes) -> bytes | None:
        self.count += 1
        if self.count not in self.which:
            return data
        garbled = bytearray(data)
        garbled[len(data) // 2] ^= 0x10
        return bytes(garbled)


def test_a_garbled_usb2ax_reply_keeps_the_sync_read() -> None:
    faults = GarbleReplies(set())
    virtual = build_bus_from_spec("MX-28:1-6", adapter="usb2ax", faults=faults)
    ids = [1, 2, 3, 4, 5, 6]
    with (
        serve_pty(virtual) as server,
        DxlBus(server.url, min_timeout_s=loaded_reply_floor_s()) as bus,
    ):
        expected = {i: bus.read(i, MX_PRESENT, 2) for i in ids}
        assert bus.sync_read(MX_PRESENT, 2, ids) == expected
        assert (bus.sync_read_mode, bus.usb2ax) == ("sync", True)
        faults.which = {faults.count + 1, faults.count + 2, faults.count + 3}
        assert bus.sync_read(MX_PRESENT, 2, ids) == expected  # read in smaller groups
        assert (bus.sync_read_mode, bus.usb2ax) == ("sync", True)


def test_a_motor_garbled_in_every_group_reply_is_read_on_its_own() -> None:
    faults = GarbleReplies(set())
    virtual = build_bus_from_spec("XL-320:1-3", protocol=2, faults=faults)
    with (
        serve_pty(virtual) as server,
        DxlBus(server.url, protocol=2, min_timeout_s=loaded_reply_floor_s()) as bus,
    ):
        expected = {i: bus.read(i, XL_PRESENT, 2) for i in (1, 2, 3)}
        # the sync read: replies 1-3; its retry asks motor 2 alone: reply 4
        faults.which = {faults.count + 2, faults.count + 4}
        assert bus.sync_read(XL_PRESENT, 2, [1, 2, 3]) == expected


def test_a_garbled_reply_does_not_wait_out_the_deadline() -> None:
    # The only reply is garbled: the exchange gives up once its bytes came (as many as the
    # reply takes) and reports it garbled, rather than waiting out its deadline for a reply
    # that will not come. The deadline is an hour: an exchange that waited it out would still be
    # waiting when the test's wait gives up (15 s at least, a wait, not a speed check).
    faults = GarbleReplies({1})
    virtual = build_bus_from_spec("XL-320:1", protocol=2, faults=faults)
    with serve_pty(virtual) as server, DxlBus(server.url, protocol=2, timeout_s=HOUR_S) as bus:
        replies: list[dict[int, StatusPacket]] = []

        def exchange() -> None:
            replies.append(bus.exchange(ping(1), [(1, 3)]))

        thread = threading.Thread(target=exchange, name="garbled-exchange", daemon=True)
        thread.start()
        assert eventually(lambda: bool(replies)), "the exchange waits out its deadline"
        thread.join()
        assert replies == [{}]
        assert (bus.stats.corrupt_packets, faults.count) == (1, 1)  # garbled; nothing resent
