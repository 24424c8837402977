"""The robot in Foxglove without ROS: a WebSocket server (``poppy serve --foxglove``) and MCAP
files (``poppy record --mcap``) written by foxglove-sdk from one publisher.

Importing this package needs the ``foxglove`` extra (foxglove-sdk): without it, a one-line
``MissingExtraError`` names it.
"""

from poppy_core.extras import require

require("foxglove", extra="foxglove")

from poppy_core.server.foxglove.mcap_file import McapRecording  # noqa: E402
from poppy_core.server.foxglove.publisher import FoxglovePublisher  # noqa: E402
from poppy_core.server.foxglove.ws_server import FoxgloveServer  # noqa: E402

__all__ = ["FoxglovePublisher", "FoxgloveServer", "McapRecording"]
