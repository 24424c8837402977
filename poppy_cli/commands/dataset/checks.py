"""The refusals of `poppy dataset` options: each a usage error (one line, exit 2) before a robot."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

SOURCES = ("--play", "--primitive", "--by-hand", "--leader")


def usage(message: str, hint: str | None = None) -> typer.BadParameter:
    return typer.BadParameter(message, param_hint=hint)


def seconds(value: float, name: str, low: float) -> float:
    from poppy_core.motion.recording_session import check_seconds

    return float(core(lambda: check_seconds(value, name, low), name))


def episode_count(episodes: int) -> int:
    from poppy_core.motion.recording_session import check_episodes

    return int(core(lambda: check_episodes(episodes), "--episodes"))


def core(call: Any, hint: str) -> Any:
    """A core check; its ArgumentError becomes a usage error (exit 2) on ``hint``."""
    from poppy_core.errors import ArgumentError

    try:
        return call()
    except ArgumentError as exc:
        raise usage(str(exc), hint) from None


def camera_specs(specs: list[str]) -> dict[str, str | None]:
    """``NAME`` (a camera of the robot's config) or ``NAME=SPEC`` (dummy[:WxH], an index, a
    device or a video file), in order."""
    from poppy_core.dataset.layout import NAME

    found: dict[str, str | None] = {}
    for text in specs:
        name, has_spec, spec = text.partition("=")
        if not NAME.fullmatch(name) or (has_spec and not spec):
            raise usage(
                f"{text!r}: give NAME or NAME=SPEC (dummy, dummy:640x480, 0, /dev/video0)",
                "--camera",
            )
        found[name] = spec if has_spec else None
    return found


def source_of(play: str | None, primitive: str | None, by_hand: bool, leader: str | None) -> str:
    """The one source of actions given, as its flag."""
    given = (play is not None, primitive is not None, by_hand, leader is not None)
    chosen = [flag for flag, there in zip(SOURCES, given, strict=True) if there]
    if len(chosen) != 1:
        raise usage(
            "give one source of actions: --play MOVE, --primitive NAME, --by-hand or "
            f"--leader PROFILE (got {', '.join(chosen) or 'none'})"
        )
    return chosen[0]


def dataset_folder(repo_id: str, root: Path | None) -> Path:
    """The dataset's folder (--root, else LeRobot's), refused unless it holds a dataset."""
    from poppy_core.dataset import layout
    from poppy_core.dataset.writer import default_root
    from poppy_core.extras import require

    require("pyarrow", extra="dataset")
    core(lambda: layout.check_repo_id(repo_id), "REPO_ID")
    folder = Path(root).expanduser() if root is not None else default_root(repo_id)
    if not (folder / layout.INFO_PATH).is_file():
        raise usage(
            f"{folder} holds no dataset (no {layout.INFO_PATH}): give its folder with --root",
            "--root",
        )
    return folder


RootOpt = typer.Option(
    None, "--root", help="Its folder. [default: $HF_LEROBOT_HOME/REPO_ID, as LeRobot's]"
)
EpisodeOpt = typer.Option(..., "--episode", min=0, help="The episode's number (from 0).")
