"""``protocol_for(1 | 2)``: the protocol object of a version number (configs keep the number)."""

from __future__ import annotations

from types import MappingProxyType

from poppy_core.errors import ProtocolError
from poppy_core.protocol.base import DxlProtocol
from poppy_core.protocol.v1 import PROTOCOL_1
from poppy_core.protocol.v2 import PROTOCOL_2

#: Every protocol object by its version number.
PROTOCOLS_BY_VERSION = MappingProxyType({p.version: p for p in (PROTOCOL_1, PROTOCOL_2)})


def protocol_for(protocol: int | DxlProtocol) -> DxlProtocol:
    """The protocol object of ``protocol`` (a version number, or already an object).

    Raises:
        ProtocolError: unknown protocol.
    """
    if isinstance(protocol, DxlProtocol):
        return protocol
    try:
        return PROTOCOLS_BY_VERSION[protocol]
    except (KeyError, TypeError):
        raise ProtocolError(f"unknown Dynamixel protocol {protocol!r} (expected 1 or 2)") from None
