"""``protocol_for(1 | 2)``: the protocol object of a version number (configs keep the number)."""

from __future__ import annotations

from types import MappingProxyType

from poppy_core.errors import ProtocolError
from poppy_core.protocol.base import DxlProtocol
from poppy_core.protocol.v1 import PROTOCOL_1
from poppy_core.protocol.v2 import PROTOCOL_2

_ALL: tuple[DxlProtocol, ...] = (PROTOCOL_1, PROTOCOL_2)
#: Every protocol object by its version number.
PROTOCOLS_BY_VERSION = MappingProxyType({proto.version: proto for proto in _ALL})
# Version numbers and the objects themselves, so one dict lookup answers either.
_LOOKUP: dict[object, DxlProtocol] = {proto.version: proto for proto in _ALL}
_LOOKUP.update({proto: proto for proto in _ALL})


def protocol_for(protocol: int | DxlProtocol) -> DxlProtocol:
    """The protocol object of ``protocol`` (a version number, or already an object).

    Raises:
        ProtocolError: unknown protocol.
    """
    try:
        return _LOOKUP[protocol]
    except (KeyError, TypeError):
        raise ProtocolError(f"unknown Dynamixel protocol {protocol!r} (expected 1 or 2)") from None
