"""The server room's libraries (the ``server`` extra), checked before any of them is imported."""

from poppy_core.extras import require

require("fastapi", "uvicorn", extra="server", feature="the web servers")
