"""Readable names for the error byte of a status packet (``decode_errors``)."""

from __future__ import annotations

from poppy_core.protocol.encoding import check_protocol

# e-manual (Protocol 1.0, Status Packet): one flag per bit, bit 7 unused.
V1_ERROR_BITS: tuple[str, ...] = (
    "input voltage",
    "angle limit",
    "overheating",
    "range",
    "checksum",
    "overload",
    "instruction",
)

# e-manual (Protocol 2.0, Status Packet): bits 0-6 hold an error number, bit 7 is the alert flag.
V2_ERROR_NUMBERS: dict[int, str] = {
    1: "result fail",
    2: "instruction error",
    3: "CRC error",
    4: "data range error",
    5: "data length error",
    6: "data limit error",
    7: "access error",
}
V2_ALERT_BIT = 0x80


def decode_errors(protocol: int, error: int) -> list[str]:
    """Readable names of the errors flagged in a status packet's error byte.

    Args:
        protocol: 1 or 2.
        error: the error byte.

    Returns:
        The names, empty when the byte reports no error. Protocol 2 gives the error number's
        name (``"error N"`` for a number the e-manual does not define) then ``"hardware alert"``
        when bit 7 is set.

    Raises:
        ProtocolError: unknown protocol.
    """
    check_protocol(protocol)
    if protocol == 1:
        return [name for bit, name in enumerate(V1_ERROR_BITS) if error & (1 << bit)]
    names: list[str] = []
    number = error & 0x7F
    if number:
        names.append(V2_ERROR_NUMBERS.get(number, f"error {number}"))
    if error & V2_ALERT_BIT:
        names.append("hardware alert")
    return names
