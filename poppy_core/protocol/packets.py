"""The two packet shapes, shared by both protocols (the protocol is picked when encoding)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class InstructionPacket:
    """A packet the host sends: target ID, instruction code and raw (unstuffed) parameters."""

    id: int
    instruction: int
    params: bytes = b""

    def __post_init__(self) -> None:
        if type(self.params) is not bytes:
            object.__setattr__(self, "params", bytes(self.params))


@dataclass(frozen=True, slots=True)
class StatusPacket:
    """A packet a device answers with: its ID, the error byte and raw (unstuffed) parameters."""

    id: int
    error: int
    params: bytes = b""

    def __post_init__(self) -> None:
        if type(self.params) is not bytes:
            object.__setattr__(self, "params", bytes(self.params))
