"""The ROS 2 tests' served robot: a virtual Ergo Jr behind ``serve --ros2`` (one per test)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING

import pytest

if TYPE_CHECKING:
    from tests.ros2.test_ros2_node import Node


@pytest.fixture
def node() -> Iterator[Node]:
    from tests.ros2.test_ros2_node import Node  # it skips without zenoh and rosbags

    served = Node()
    try:
        yield served
    finally:
        served.close()
