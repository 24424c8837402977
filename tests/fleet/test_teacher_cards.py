"""The teacher page's robot cards: what a card says of a robot that left."""

from __future__ import annotations

import pytest

pytest.importorskip("zenoh")

from poppy_core.server.teacher.watch import Card


def test_a_robot_that_left_is_not_ok_even_with_a_fresh_healthy_state() -> None:
    # its last health said ok and its last state is a moment old: it still left
    card = Card("jr9", alive=False, health={"ok": True}, state_at=100.0)
    shown = card.as_dict(now=100.5)
    assert shown["health"] == "left the network"
    assert shown["ok"] is False
    card.alive = True
    assert card.as_dict(now=100.5)["ok"] is True
