"""A MuJoCo model file and the mesh files it names, read for ``MjModel.from_xml_string``."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from poppy_core.errors import ConfigError

MAX_MODEL_BYTES = 4 * 1024 * 1024  # an MJCF text (the profiles' are ~20 kB)
MAX_ASSETS_BYTES = 64 * 1024 * 1024  # all its mesh files together (the profiles' ~1 MB)


def read_model(path: Path) -> tuple[str, dict[str, bytes]]:
    """The MJCF text at ``path`` and its assets: every ``<mesh file>`` under the compiler's
    ``meshdir`` (relative to the model's folder), keyed as MuJoCo looks them up.

    Raises:
        ConfigError: the model or a mesh file is missing, unreadable or too large.
    """
    try:
        if path.stat().st_size > MAX_MODEL_BYTES:
            raise ConfigError("the model file is too large", file=str(path))
        xml = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"cannot read the simulation model: {exc}", file=str(path)) from exc
    return xml, model_assets(xml, path.parent, str(path))


def model_assets(xml: str, folder: Path, source: str = "model") -> dict[str, bytes]:
    """The mesh files the MJCF ``xml`` names, read from ``folder`` (its ``meshdir`` applied)."""
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
        try:
            data = file.read_bytes()
        except OSError as exc:
            raise ConfigError(f"cannot read a mesh of the model: {exc}", file=str(file)) from exc
        total += len(data)
        if total > MAX_ASSETS_BYTES:
            raise ConfigError("the model's mesh files are too large", file=str(file))
        assets[name] = data
    return assets
