"""A MuJoCo model file and the mesh files it names, read for ``MjModel.from_xml_string``."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from poppy_core.errors import ConfigError

MESH_DIR = "meshes"  # profiles/<robot>/meshes/: the URDF's visual meshes (binary STL)
MAX_MODEL_BYTES = 4 * 1024 * 1024  # an MJCF text (the profiles' are ~20 kB)
MAX_ASSETS_BYTES = 64 * 1024 * 1024  # all its mesh files together (the profiles' ~1 MB)


def read_model(path: Path, fallback: Path | None = None) -> tuple[str, dict[str, bytes]]:
    """The MJCF text at ``path`` and its assets (``model_assets``).

    Raises:
        ConfigError: the model or a mesh file is missing, unreadable or too large.
    """
    xml = read_xml(path)
    return xml, model_assets(xml, path.parent, str(path), fallback)


def read_xml(path: Path) -> str:
    """The MJCF text at ``path``, within ``MAX_MODEL_BYTES``.

    Raises:
        ConfigError: missing, unreadable or too large.
    """
    try:
        if path.stat().st_size > MAX_MODEL_BYTES:
            raise ConfigError("the model file is too large", file=str(path))
        return path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"cannot read the simulation model: {exc}", file=str(path)) from exc


def model_assets(
    xml: str, folder: Path, source: str = "model", fallback: Path | None = None
) -> dict[str, bytes]:
    """Every ``<mesh file>`` the MJCF ``xml`` names, keyed as MuJoCo looks them up: read under
    its compiler's ``meshdir`` in ``folder``, else (a scene borrowing the robot's meshes) in
    ``fallback``."""
    try:
        root = ET.fromstring(xml)
    except ET.ParseError as exc:
        raise ConfigError(f"the simulation model is not XML: {exc}", file=source) from exc
    compiler = root.find("compiler")
    meshdir = compiler.get("meshdir", "") if compiler is not None else ""
    assets: dict[str, bytes] = {}
    total = 0
    for mesh in root.iter("mesh"):
        name = mesh.get("file")
        if not name or name in assets:
            continue
        file = folder / meshdir / name
        if not file.is_file() and fallback is not None and (fallback / name).is_file():
            file = fallback / name
        try:
            data = file.read_bytes()
        except OSError as exc:
            raise ConfigError(f"cannot read a mesh of the model: {exc}", file=str(file)) from exc
        total += len(data)
        if total > MAX_ASSETS_BYTES:
            raise ConfigError("the model's mesh files are too large", file=str(file))
        assets[name] = data
    return assets
