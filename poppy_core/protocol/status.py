"""Readable names for the error byte of a status packet (``decode_errors``)."""

from __future__ import annotations

from poppy_core.protocol.base import DxlProtocol
from poppy_core.protocol.v1 import V1_ERROR_BITS
from poppy_core.protocol.v2 import V2_ALERT_BIT, V2_ERROR_NUMBERS
from poppy_core.protocol.versions import protocol_for

__all__ = ["V1_ERROR_BITS", "V2_ALERT_BIT", "V2_ERROR_NUMBERS", "decode_errors"]


def decode_errors(protocol: int | DxlProtocol, error: int) -> list[str]:
    """Readable names of the errors flagged in a status packet's error byte.

    Args:
        protocol: 1 or 2 (or its protocol object).
        error: the error byte.

    Returns:
        The names, empty when the byte reports no error. Protocol 2 gives the error number's
        name (``"error N"`` for a number the e-manual does not define) then ``"hardware alert"``
        when bit 7 is set.

    Raises:
        ProtocolError: unknown protocol.
    """
    return protocol_for(protocol).decode_errors(error)
