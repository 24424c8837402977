"""Hypothesis strategies shared by the protocol tests (imported as a sibling module)."""

from __future__ import annotations

from hypothesis import strategies as st

from poppy_core.protocol import BROADCAST_ID, InstructionPacket, StatusPacket

# Parameters rich in header bytes, so FF FF FD patterns and fake headers show up often.
header_heavy_bytes = st.lists(
    st.one_of(st.sampled_from([0xFF, 0xFD, 0x00, 0x55]), st.integers(0, 255)), max_size=60
).map(bytes)

motor_ids = st.integers(0, 253)
protocols = st.sampled_from([1, 2])
kinds = st.sampled_from(["instruction", "status"])


def instruction_packets(max_params: int = 60) -> st.SearchStrategy[InstructionPacket]:
    return st.builds(
        InstructionPacket,
        id=st.one_of(motor_ids, st.just(BROADCAST_ID)),
        # 0x55 is the status marker in protocol 2, never an instruction.
        instruction=st.integers(0, 255).filter(lambda code: code != 0x55),
        params=header_heavy_bytes.map(lambda b: b[:max_params]),
    )


def status_packets() -> st.SearchStrategy[StatusPacket]:
    return st.builds(
        StatusPacket, id=motor_ids, error=st.integers(0, 255), params=header_heavy_bytes
    )


def packets_of(kind: str) -> st.SearchStrategy[InstructionPacket | StatusPacket]:
    """Packets of the kind a decoder of ``kind`` returns."""
    if kind == "instruction":
        return instruction_packets()
    return status_packets()
