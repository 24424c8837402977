"""The robot's URDF and meshes for Foxglove's asset requests (``package://`` URLs).

The URDF names its meshes ``package://PoppyErgoJr/meshes/NAME.STL``; Foxglove's 3D panel asks
the server it is connected to for them (the ``fetchAsset`` request). Only the URDF itself and
the files of its ``meshes`` folder are served, under the package names the URDF uses.
"""

from __future__ import annotations

import logging
import re
from pathlib import Path

logger = logging.getLogger(__name__)

PACKAGE = re.compile(r"package://([A-Za-z0-9_.-]+)/")
MESH_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,127}\.(stl|STL|dae|DAE)")
MAX_BYTES = 32 * 1024 * 1024


class RobotAssets:
    """The files a URDF at ``urdf`` names: ``fetch(uri)`` gives their bytes, or None.

    Args:
        urdf: the URDF file (its meshes are in ``meshes/`` beside it).
        text: its text (the package names are read from it).
    """

    def __init__(self, urdf: Path, text: str) -> None:
        self.urdf = urdf
        self.meshes = urdf.parent / "meshes"
        self.packages = frozenset(PACKAGE.findall(text))
        """The package names the URDF's ``package://`` URLs use."""

    def uri(self, relative: str) -> str | None:
        """``package://PACKAGE/relative`` (the URDF's first package), or None without one."""
        if not self.packages:
            return None
        return f"package://{min(self.packages)}/{relative}"

    def path(self, uri: str) -> Path | None:
        """The file ``uri`` names, or None when it is not one of the robot's."""
        match = PACKAGE.match(uri)
        if match is None or match.group(1) not in self.packages:
            return None
        rest = uri[match.end() :]
        if rest == self.urdf.name:
            return self.urdf
        folder, _, name = rest.partition("/")
        if folder == "meshes" and MESH_NAME.fullmatch(name):
            path = self.meshes / name
            return path if path.is_file() else None
        return None

    def fetch(self, uri: str) -> bytes | None:
        """The bytes of the file ``uri`` names (None: not found, the client is told so)."""
        path = self.path(uri)
        if path is None:
            logger.info("Foxglove asked for %r: not one of the robot's files", uri[:200])
            return None
        try:
            with path.open("rb") as stream:
                data = stream.read(MAX_BYTES + 1)
        except OSError as exc:
            logger.warning("Foxglove asked for %s: %s", path, exc)
            return None
        return data if len(data) <= MAX_BYTES else None
