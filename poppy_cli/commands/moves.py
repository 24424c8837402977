"""`poppy moves ...`: the move library: list, show, plot, remove, export and import moves."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from poppy_cli import complete
from poppy_cli.options import JsonOpt
from poppy_cli.output import EXIT_USAGE, console, error_line, print_json, styled

app = typer.Typer(
    help="The move library (recorded with `poppy record`): list, show, plot, rm, export, import.",
    no_args_is_help=True,
)

ForceOpt = typer.Option(False, "--force", "-f", help="Replace an existing file.")
NameArg = typer.Argument(
    ..., help="Library name of the move, or a file path.", autocompletion=complete.moves
)


def _header(path: Path) -> dict[str, Any]:
    from poppy_core.motion import read_move

    move = read_move(path)
    return {
        "name": path.stem,
        "path": str(path),
        "format": "pypot" if path.suffix.lower() == ".json" else "poppy",
        "size_bytes": path.stat().st_size,
        "framerate": move.framerate,
        "frames": len(move),
        "duration_s": round(move.duration_s, 3),
        "motors": list(move.motors),
        "speeds": move.speeds is not None,
        "metadata": move.metadata,
        "stats": [
            {"name": name, **{k: round(v, 2) + 0.0 for k, v in values.items()}}  # no "-0.0"
            for name, values in move.stats().items()
        ],
    }


@app.command("list")
def list_cmd(json_output: bool = JsonOpt) -> None:
    """List the moves of the library (folder: POPPY_MOVES_DIR or the user data folder)."""
    from rich.table import Table

    from poppy_core.errors import ConfigError
    from poppy_core.motion import list_moves, moves_dir

    rows: list[dict[str, Any]] = []
    for entry in list_moves():
        row: dict[str, Any] = {
            "name": entry.name,
            "path": str(entry.path),
            "format": entry.format,
            "size_bytes": entry.size_bytes,
        }
        try:
            header = _header(entry.path)
            row.update(
                {k: header[k] for k in ("frames", "framerate", "duration_s", "motors")}, error=None
            )
        except ConfigError as exc:
            row["error"] = str(exc)
        rows.append(row)
    if json_output:
        print_json({"folder": str(moves_dir()), "moves": rows})
        return
    if not rows:
        console.print(f"no move in {moves_dir()} (record one with `poppy record NAME`)")
        return
    table = Table(title=f"moves in {moves_dir()}")
    for column in ("name", "format", "duration", "frames", "rate", "motors", "size"):
        table.add_column(column, justify="right" if column in ("duration", "frames") else "left")
    for row in rows:
        if row.get("error"):
            table.add_row(row["name"], row["format"], styled("[red]unreadable[/]"), "", "", "", "")
            continue
        table.add_row(
            row["name"],
            row["format"],
            f"{row['duration_s']:.2f} s",
            str(row["frames"]),
            f"{row['framerate']:g} Hz",
            ", ".join(row["motors"]),
            _size(row["size_bytes"]),
        )
    console.print(table)


def _size(count: int) -> str:
    for unit in ("B", "kB", "MB"):
        if count < 1000 or unit == "MB":
            return f"{count:.0f} {unit}" if unit == "B" else f"{count:.1f} {unit}"
        count = count / 1000  # type: ignore[assignment]
    return str(count)


@app.command("show")
def show(name: str = NameArg, json_output: bool = JsonOpt) -> None:
    """Show a move's header and per-motor statistics (min, max, start, end)."""
    from rich.table import Table

    from poppy_core.motion import move_path

    header = _header(move_path(name))
    if json_output:
        print_json(header)
        return
    console.print(
        styled(
            "[bold]{}[/] ({}, {}): {} frames at {} Hz = {} s",
            header["name"],
            header["format"],
            _size(header["size_bytes"]),
            header["frames"],
            f"{header['framerate']:g}",
            f"{header['duration_s']:.2f}",
        )
    )
    for key, value in header["metadata"].items():
        console.print(f"  {key}: {value}")
    table = Table(title="positions (°)")
    for column in ("motor", "start", "end", "min", "max", "range"):
        table.add_column(column, justify="left" if column == "motor" else "right")
    for stats in header["stats"]:
        values = [
            f"{stats[k]:.1f}" if k in stats else "" for k in ("start", "end", "min", "max", "range")
        ]
        table.add_row(stats["name"], *values)
    console.print(table)


@app.command("plot")
def plot(
    name: str = NameArg,
    output: Path = typer.Option(
        ..., "--output", "-o", help="Image file (png, svg, pdf), or a folder (NAME.png)."
    ),
    force: bool = ForceOpt,
    json_output: bool = JsonOpt,
) -> None:
    """Draw each motor's trajectory against time into an image (matplotlib)."""
    import io

    from poppy_core.extras import require
    from poppy_core.files import output_path, write_file
    from poppy_core.motion import load_move, move_path

    require("matplotlib", extra="plot", feature="poppy moves plot")
    path = move_path(name)
    target = output_path(output, default_name=f"{path.stem}.png", replace=force)
    image_format = target.suffix.lower().lstrip(".") or "png"
    if image_format not in ("png", "svg", "pdf", "jpg", "jpeg"):
        error_line(f"{target}: write a .png, .svg, .pdf or .jpg")
        raise typer.Exit(EXIT_USAGE)
    move = load_move(path)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(figsize=(10, 5))
    times = move.times()
    for index, motor in enumerate(move.motors):
        axes.plot(times, move.positions[:, index], label=motor)
    axes.set_xlabel("time (s)")
    axes.set_ylabel("position (°)")
    axes.set_title(f"{path.stem}: {len(move)} frames at {move.framerate:g} Hz")
    axes.grid(True, alpha=0.3)
    if move.motors:
        axes.legend(loc="best", fontsize="small")
    image = io.BytesIO()
    figure.savefig(image, dpi=100, format=image_format)
    plt.close(figure)
    write_file(target, image.getvalue(), replace=force)
    if json_output:
        print_json({"move": str(path), "output": str(target)})
        return
    console.print(f"plotted {len(move.motors)} motors of {path.stem} into {target}")


@app.command("rm")
def rm(
    name: str = NameArg,
    yes: bool = typer.Option(False, "--yes", "-y", help="Do not ask for confirmation."),
    json_output: bool = JsonOpt,
) -> None:
    """Delete a move (asks first unless --yes)."""
    from poppy_core.motion import delete_move, move_path

    path = move_path(name)
    if not yes:
        from poppy_cli.prompts import require_yes

        require_yes(f"delete {path}?", declined="not deleted")
    delete_move(path)
    if json_output:
        print_json({"deleted": str(path)})
        return
    console.print(f"deleted {path}")


@app.command("export")
def export(
    name: str = NameArg,
    output: Path = typer.Option(..., "--output", "-o", help="File to write, or a folder."),
    fmt: str | None = typer.Option(
        None, "--format", help="pypot (JSON) or poppy (compact); default from the suffix."
    ),
    force: bool = ForceOpt,
    json_output: bool = JsonOpt,
) -> None:
    """Write a move to a file in pypot's JSON (old tools can play it) or poppy's format.

    Into a folder, the file is named after the move. An existing file is replaced only with
    --force; a folder, a link, a FIFO or a device never.
    """
    from poppy_core.motion import FORMATS, export_move

    if fmt is not None and fmt not in FORMATS:
        raise typer.BadParameter(f"{fmt!r} is not {' or '.join(FORMATS)}", param_hint="--format")
    written = export_move(name, output, fmt, replace=force)
    chosen = fmt or ("pypot" if written.suffix.lower() == ".json" else "poppy")
    if json_output:
        print_json({"output": str(written), "format": chosen, "size_bytes": written.stat().st_size})
        return
    console.print(f"exported {name} as {chosen} to {written}")


@app.command("import")
def import_cmd(
    file: Path = typer.Argument(..., help="A move file: pypot JSON or poppy .move."),
    name: str | None = typer.Option(None, "--name", "-n", help="Library name (default: stem)."),
    force: bool = typer.Option(False, "--force", "-f", help="Replace a move of that name."),
    json_output: bool = JsonOpt,
) -> None:
    """Copy a move file into the library (stored in poppy's compact format)."""
    from poppy_core.motion import import_move, read_move

    target = import_move(file, name, overwrite=force)
    move = read_move(target)
    if json_output:
        print_json(
            {
                "name": target.stem,
                "path": str(target),
                "frames": len(move),
                "motors": list(move.motors),
            }
        )
        return
    console.print(f"imported {file} as {target.stem} ({len(move)} frames) into {target}")
