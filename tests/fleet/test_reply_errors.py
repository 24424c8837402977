"""What a Zenoh request reports from the error replies it got instead of an answer: Zenoh's
"Timeout" is the robot not answering in time however many sessions sent it (the client's own
and the robot's session or a router that timed the query out too: a loaded CI machine got two),
and any other error is named once, as it came.

Replies are built like Zenoh's (``ok`` None, ``err.payload.to_bytes()``) so the order and count
that a loaded machine produces can be given exactly.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import pytest

from poppy_core.errors import BusTimeout, CommunicationError
from poppy_core.remote.zenoh_client import answer_of


def error_reply(text: str) -> Any:
    payload = SimpleNamespace(to_bytes=lambda: text.encode())
    return SimpleNamespace(ok=None, err=SimpleNamespace(payload=payload))


@pytest.mark.parametrize("count", [1, 2, 3])
def test_timeouts_from_every_session_are_one_timeout(count: int) -> None:
    replies = [error_reply("Timeout") for _ in range(count)]
    with pytest.raises(BusTimeout, match=r"zenoh:jr-a: no answer within 1 s \(is the robot"):
        answer_of("zenoh:jr-a", replies, 1.0, 1.002)


def test_no_reply_at_all_after_the_timeout_is_a_timeout() -> None:
    with pytest.raises(BusTimeout, match="no answer within 2 s"):
        answer_of("zenoh:jr-a", [], 2.0, 2.01)


def test_no_reply_at_once_is_a_robot_no_one_serves() -> None:
    with pytest.raises(CommunicationError, match="no robot of that name"):
        answer_of("zenoh:nobody", [], 2.0, 0.01)


def test_another_error_is_named_once_beside_a_timeout() -> None:
    replies = [error_reply("Timeout"), error_reply("queryable closed"), error_reply("Timeout")]
    with pytest.raises(CommunicationError) as caught:
        answer_of("zenoh:jr-a", replies, 1.0, 1.0)
    assert not isinstance(caught.value, BusTimeout)
    assert str(caught.value).startswith("zenoh:jr-a: Timeout; queryable closed")
    assert str(caught.value).count("Timeout") == 1
