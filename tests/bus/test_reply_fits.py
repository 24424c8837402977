"""Which replies a transaction keeps: one rule (``reply_fits``) for single and multi-reply reads."""

from __future__ import annotations

from poppy_core.bus.replies import reply_fits
from poppy_core.protocol import StatusPacket

OVERHEAT_P1 = 0x04  # protocol 1 alarm bit: the instruction still ran
RANGE_P1 = 0x08  # protocol 1 error bit: refused
ALERT_P2 = 0x80  # protocol 2 hardware alert alone: still ran
DATA_RANGE_P2 = 0x04  # protocol 2 error number: refused


def test_a_reply_of_the_asked_size_is_kept_whatever_its_bits() -> None:
    for protocol, error in ((1, 0), (1, OVERHEAT_P1), (1, RANGE_P1), (2, ALERT_P2)):
        assert reply_fits(protocol, StatusPacket(1, error, b"\x01\x02"), 2)


def test_a_refusal_is_kept_without_data_to_be_reported() -> None:
    assert reply_fits(1, StatusPacket(1, RANGE_P1, b""), 2)
    assert reply_fits(2, StatusPacket(1, DATA_RANGE_P2, b""), 4)


def test_another_size_without_refusal_is_a_late_answer_set_aside() -> None:
    assert not reply_fits(1, StatusPacket(1, 0, b""), 2)  # a write's late status
    assert not reply_fits(1, StatusPacket(1, OVERHEAT_P1, b""), 2)  # alarm only: not a refusal
    assert not reply_fits(2, StatusPacket(1, ALERT_P2, b"\x00"), 2)
