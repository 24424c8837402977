"""Emulator faults of a busy machine: the first replies lost, or held back."""

from __future__ import annotations

from poppy_core.emulator import FaultInjector


class DropFirst(FaultInjector):
    """Loses the first ``count`` replies, as replies late on a busy machine."""

    def __init__(self, count: int) -> None:
        super().__init__()
        self.left = count

    def filter_reply(self, data: bytes) -> bytes | None:
        self.left -= 1
        return None if self.left >= 0 else data


class LateFirst(FaultInjector):
    """Holds the first ``count`` replies back ``delay_s``, as an emulator the OS ran late."""

    def __init__(self, count: int, delay_s: float) -> None:
        super().__init__()
        self.left = count
        self.delay_s = delay_s

    def filter_reply(self, data: bytes) -> bytes | None:
        self.left -= 1
        self._extra_delay_s = self.delay_s if self.left >= 0 else 0.0
        return data


class LateAfter(FaultInjector):
    """Holds back ``delay_s`` the replies after the first ``skip``, ``count`` of them: the OS ran
    the emulator late in the middle of a conversation (the replies behind wait their turn)."""

    def __init__(self, skip: int, count: int, delay_s: float) -> None:
        super().__init__()
        self.seen = 0
        self.skip = skip
        self.count = count
        self.delay_s = delay_s

    def filter_reply(self, data: bytes) -> bytes | None:
        self.seen += 1
        late = self.skip < self.seen <= self.skip + self.count
        self._extra_delay_s = self.delay_s if late else 0.0
        return data
