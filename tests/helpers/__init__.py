"""Helpers shared by the test folders (import them from here, never from a ``conftest``)."""

from tests.helpers.waiting import eventually

__all__ = ["eventually"]
