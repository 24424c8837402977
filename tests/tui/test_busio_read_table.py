"""The TUI's control table read: a register that fails once on an unreliable line is asked again
before it shows as unknown ("?"); one that never answers stays unknown, and the rest are read.

A busy machine's emulator missed the block read and one register read (the motor panel's snapshot
showed "?" for model_number and i_gain); the bus here fails as a line does, on the requests given.
"""

from __future__ import annotations

from typing import Any

from poppy_cli.tui.busio import read_table
from poppy_core.errors import BusTimeout
from poppy_core.models import model_by_name

MODEL = model_by_name("XL-320")


class FlakyBus:
    """Answers zeros, except the block read and each register's first read (``once``) or every
    read of the registers at ``never``: those time out."""

    def __init__(self, never: tuple[int, ...] = ()) -> None:
        self.never = never
        self.asked: list[tuple[int, int]] = []

    def read(self, motor_id: int, address: int, size: int) -> bytes:
        del motor_id
        first = (address, size) not in self.asked
        self.asked.append((address, size))
        if size == MODEL.table_size or first or address in self.never:
            raise BusTimeout("no reply")
        return bytes(size)


def test_a_register_that_failed_once_is_read_again() -> None:
    rows = read_table(FlakyBus(), 1, MODEL)  # type: ignore[arg-type]
    assert rows and all(row.value is not None for row in rows)


def test_a_register_that_never_answers_stays_unknown_and_the_rest_are_read() -> None:
    model_number = MODEL.register("model_number")
    rows: list[Any] = read_table(FlakyBus(never=(model_number.address,)), 1, MODEL)  # type: ignore[arg-type]
    unknown = [row.register.name for row in rows if row.value is None]
    assert unknown == ["model_number"]
