"""What a primitive's failure keeps: the exception's type, message and traceback text."""

from __future__ import annotations

import traceback
from dataclasses import dataclass
from typing import Literal

State = Literal["idle", "running", "paused", "stopped", "failed"]
"""A primitive's state (``Primitive.state``)."""


@dataclass(frozen=True)
class PrimitiveFailure:
    """Why a primitive failed: the exception's type, its message and the traceback text."""

    type: str
    message: str
    traceback: str

    @classmethod
    def of(cls, exc: BaseException) -> PrimitiveFailure:
        """The failure ``exc`` is, its traceback formatted once."""
        text = "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))
        return cls(type(exc).__name__, str(exc), text)

    @property
    def one_line(self) -> str:
        """``"Type: message"``, for a status line."""
        return f"{self.type}: {self.message}" if self.message else self.type

    def to_dict(self) -> dict[str, str]:
        """Plain values (for JSON)."""
        return {"type": self.type, "message": self.message, "traceback": self.traceback}
