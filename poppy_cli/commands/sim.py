"""`poppy sim`: serve a MuJoCo-simulated robot's buses like `poppy emulate`, or render it."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
from pathlib import Path
from typing import Any

import typer

from poppy_cli import complete
from poppy_cli.options import finite, profile_option
from poppy_cli.output import (
    EXIT_FAILURE,
    EXIT_USAGE,
    console,
    err_console,
    error_line,
    styled,
)

RENDER_PACKAGES = "libegl1 libgl1 (EGL) or libosmesa6 (OSMesa)"

app = typer.Typer(
    help="Simulate a robot with MuJoCo: serve its buses (like `poppy emulate`) or render it.",
    invoke_without_command=True,
    no_args_is_help=False,
)


# ---------------------------------------------------------------------------------- serving


def _display() -> str | None:
    return os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY") or None


def _open_viewer(simulation: Any) -> Any:
    """MuJoCo's passive viewer on the simulation, or None with one line saying why not."""
    if _display() is None:
        err_console.print(
            "--view: no display ($DISPLAY and $WAYLAND_DISPLAY are unset), so no viewer "
            "window; serving without it (render images with `poppy sim render`)"
        )
        return None
    from poppy_core.extras import require

    require("mujoco", extra="sim", feature="--view")
    try:
        import mujoco.viewer

        with simulation.lock:  # the drawn world (the robot's meshes), posed as the physics
            return mujoco.viewer.launch_passive(simulation.view_model, simulation.view())
    except Exception as exc:  # any GL/GLFW failure: keep serving
        err_console.print(f"--view: cannot open MuJoCo's viewer ({exc}); serving without it")
        return None


def _serve_tcp_instead(servers: dict[str, Any], tcp: str) -> dict[str, Any]:
    from poppy_cli.commands.emulate import parse_hostport
    from poppy_core.emulator import serve_tcp

    host, port = parse_hostport(tcp)
    moved: dict[str, Any] = {}
    try:
        for index, (name, server) in enumerate(servers.items()):
            server.stop()
            moved[name] = serve_tcp(server.bus, host, port + index if port else 0)
    except BaseException:
        for server in moved.values():
            server.stop()
        raise
    return moved


def _serve(profile: str, speed: float, tcp: str | None, view: bool) -> None:
    from poppy_core.robot import load_profile
    from poppy_core.robot.factory import start_emulators, start_simulation

    config = load_profile(profile)
    stop = threading.Event()
    # Handlers go in before the URLs are printed: a client may stop us as soon as it reads one.
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.set())
    simulation = start_simulation(config)
    simulation.speed = speed
    servers: dict[str, Any] = {}
    viewer: Any = None
    try:
        servers = start_emulators(config, simulation)
        if tcp:
            servers = _serve_tcp_instead(servers, tcp)
        simulation.start()
        for server in servers.values():
            sys.stdout.write(server.url + "\n")
        sys.stdout.flush()
        for name, server in servers.items():
            bus = server.bus
            ids = ", ".join(str(m.id) for m in bus.motors)
            err_console.print(
                styled(
                    "[green]simulating[/] {}",
                    f"{profile} {name}: {len(bus.motors)} motors "
                    f"(ids {ids}), protocol {bus.protocol} at {bus.baudrate} bps on "
                    f"{server.url}, MuJoCo at {speed:g}× real time — Ctrl-C to stop",
                )
            )
        viewer = _open_viewer(simulation) if view else None
        while not stop.wait(1 / 30 if viewer is not None else 0.5):
            if viewer is not None:
                if not viewer.is_running():
                    viewer = None
                    continue
                with simulation.lock:
                    simulation.view()
                viewer.sync()
    finally:
        if viewer is not None:
            viewer.close()
        for server in servers.values():
            server.stop()
        simulation.close()


@app.callback()
def sim(
    ctx: typer.Context,
    profile: str | None = profile_option(
        "Robot profile with a simulation model: ergo-jr, torso, humanoid."
    ),
    speed: float = typer.Option(
        1.0,
        "--speed",
        "-s",
        min=0.01,
        max=1000.0,
        callback=finite,
        help="Simulated seconds per real second (1 = real time).",
    ),
    pty: bool = typer.Option(False, "--pty", help="Serve on pseudo-terminals (the default)."),
    tcp: str | None = typer.Option(
        None, "--tcp", help="Serve on TCP HOST:PORT instead (one port per bus; 0: any free)."
    ),
    view: bool = typer.Option(False, "--view", help="Open MuJoCo's viewer (needs a display)."),
) -> None:
    """Serve the simulated robot's buses: print each bus's pty path (or socket:// URL) on its
    own line, then run the physics until Ctrl-C. `poppy scan`, `poppy motor`, `poppy robot
    --port` work on it as on hardware.
    """
    if ctx.invoked_subcommand is not None:
        return
    if profile is None:
        error_line("give --profile NAME (ergo-jr, torso or humanoid): poppy sim --profile ergo-jr")
        raise typer.Exit(EXIT_USAGE)
    if pty and tcp:
        error_line("give either --pty or --tcp, not both")
        raise typer.Exit(EXIT_USAGE)
    _serve(profile, speed, tcp, view)


# ---------------------------------------------------------------------------------- rendering


def _gl_works(backend: str) -> bool:
    """Whether MuJoCo can open an offscreen context with ``backend`` (tried in a subprocess)."""
    code = "import mujoco; mujoco.GLContext(8, 8).make_current()"
    env = dict(os.environ, MUJOCO_GL=backend, PYOPENGL_PLATFORM=backend)
    try:
        done = subprocess.run(
            [sys.executable, "-c", code], env=env, capture_output=True, timeout=30, check=False
        )
    except (OSError, subprocess.TimeoutExpired):
        return False
    return done.returncode == 0


def choose_gl_backend() -> str | None:
    """Set ``MUJOCO_GL`` for offscreen rendering: the user's, else glfw with a display, else
    egl, else osmesa. None when nothing works (before mujoco is imported)."""
    if "MUJOCO_GL" in os.environ:
        return os.environ["MUJOCO_GL"]
    if "mujoco" in sys.modules:  # already chosen at import
        return os.environ.get("MUJOCO_GL", "glfw")
    candidates = (["glfw"] if _display() else []) + ["egl", "osmesa"]
    for backend in candidates:
        if _gl_works(backend):
            os.environ["MUJOCO_GL"] = backend
            if backend != "glfw":
                os.environ.setdefault("PYOPENGL_PLATFORM", backend)
            return backend
    return None


def _no_gl(detail: str) -> typer.Exit:
    error_line(
        f"cannot render offscreen ({detail}): install the Debian packages {RENDER_PACKAGES} "
        "(`make sim-deps`), or set MUJOCO_GL"
    )
    return typer.Exit(EXIT_FAILURE)


def _render_with_progress(
    profile: str, move_ref: str | None, camera: str | None, width: int, height: int, backend: str
) -> list[Any]:
    """Render through ``poppy_core.motion.render``, a bar of frames and time left on a terminal."""
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    from poppy_core.errors import ConfigError
    from poppy_core.motion import load_move
    from poppy_core.motion.render import RenderProgress, frame_count, render_frames
    from poppy_core.robot import load_profile

    config = load_profile(profile)
    move = load_move(move_ref) if move_ref is not None else None
    if move is not None:
        unknown = [m for m in move.motors if m not in config.motors]
        if unknown:
            raise ConfigError(
                f"move {move_ref!r} drives motors {profile} has not: {', '.join(unknown)}",
                field="move",
            )
    columns = (
        TextColumn("{task.description}", markup=False),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("frames ·"),
        TimeElapsedColumn(),
        TextColumn("·"),
        TimeRemainingColumn(),
        TextColumn("left"),
    )
    with Progress(*columns, console=err_console, transient=True) as bar:
        task = bar.add_task(f"rendering {profile} ({backend})", total=frame_count(move))

        def on_progress(event: RenderProgress) -> None:
            bar.update(task, completed=event.done, total=event.total)

        return render_frames(config, move, camera, width, height, progress=on_progress)


def save_frames(frames: list[Any], output: Path, *, replace: bool = False) -> Path:
    """One frame to a PNG (or any still format Pillow writes), all frames to a GIF.

    The image is encoded in memory and written by ``poppy_core.files.write_file`` (atomic,
    never over something that is not a regular file).
    """
    import io

    from PIL import Image

    from poppy_core.files import write_file
    from poppy_core.motion.render import GIF_FPS

    images = [Image.fromarray(frame) for frame in frames]
    suffix = output.suffix.lower()
    image = io.BytesIO()
    if suffix == ".gif":
        images[0].save(
            image,
            format="GIF",
            save_all=True,
            append_images=images[1:],
            duration=round(1000 / GIF_FPS),
            loop=0,
        )
    else:
        images[-1].save(image, format="JPEG" if suffix in (".jpg", ".jpeg") else "PNG")
    return write_file(output, image.getvalue(), replace=replace)


@app.command("render")
def render(
    output: Path = typer.Option(
        ..., "--output", "-o", help="out.png (a still) or out.gif, or a folder (PROFILE.png/gif)."
    ),
    profile: str = profile_option("Robot profile to render.", default="ergo-jr"),
    move: str | None = typer.Option(
        None,
        "--move",
        help="Play this move (library name or file) and render it (use a .gif).",
        autocompletion=complete.moves,
    ),
    camera: str | None = typer.Option(
        "front",
        "--camera",
        help="View: front, side or top (each frames the robot and all it can reach), "
        "camera (the robot's own), or free (MuJoCo's default view).",
    ),
    width: int = typer.Option(640, "--width", min=16, max=4096, help="Image width (pixels)."),
    height: int = typer.Option(480, "--height", min=16, max=4096, help="Image height (pixels)."),
    force: bool = typer.Option(False, "--force", "-f", help="Replace an existing file."),
) -> None:
    """Render the simulated robot offscreen (EGL or OSMesa, no GPU needed) to a PNG, or a
    move played in the simulation to a GIF (15 frames per second)."""
    from poppy_core.errors import ConfigError
    from poppy_core.extras import require
    from poppy_core.files import output_path

    require("mujoco", "PIL", extra="sim", feature="poppy sim render")
    default = f"{profile}.gif" if move is not None else f"{profile}.png"
    output = output_path(output, default_name=default, replace=force)  # refused before rendering
    suffix = output.suffix.lower()
    if suffix not in (".png", ".gif", ".jpg", ".jpeg"):
        error_line(f"{output}: write a .png, .jpg or .gif")
        raise typer.Exit(EXIT_USAGE)
    backend = choose_gl_backend()
    if backend is None:
        raise _no_gl("no working OpenGL backend: EGL and OSMesa failed")
    chosen = None if camera in (None, "free") else camera
    try:
        frames = _render_with_progress(profile, move, chosen, width, height, backend)
    except ConfigError as exc:
        if exc.field == "MUJOCO_GL":
            raise _no_gl(str(exc)) from None
        raise
    except ValueError as exc:  # mujoco: unknown camera
        error_line(
            f"{exc} (the models' cameras: front, side, top, camera; 'free' is the default view)"
        )
        raise typer.Exit(EXIT_USAGE) from None
    if suffix != ".gif" and len(frames) > 1:
        err_console.print(f"a still image holds one frame: the last of {len(frames)} is saved")
    save_frames(frames, output, replace=force)
    console.print(
        f"wrote {output} ({width}×{height}, {len(frames) if suffix == '.gif' else 1} "
        f"frame{'s' if suffix == '.gif' and len(frames) > 1 else ''}, {backend})"
    )
