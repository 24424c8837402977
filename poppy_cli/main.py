"""Entry point of `poppy`: composes the command groups and turns errors into one line."""

from __future__ import annotations

import logging
import sys

import typer
from typer import _click as click  # typer vendors Click: its exceptions live here

from poppy_cli import state
from poppy_cli.commands import calibrate as calibrate_cmd
from poppy_cli.commands import (
    camera,
    config,
    dataset,
    demo,
    doctor,
    emulate,
    fleet,
    motor_setup,
    ports,
    scan,
)
from poppy_cli.commands import moves as moves_cmd
from poppy_cli.commands import notebook as notebook_cmd
from poppy_cli.commands import play as play_cmd
from poppy_cli.commands import primitive as primitive_cmd
from poppy_cli.commands import reach as reach_cmd
from poppy_cli.commands import record as record_cmd
from poppy_cli.commands import serve as serve_cmd
from poppy_cli.commands import service as service_cmd
from poppy_cli.commands import setup as setup_cmd
from poppy_cli.commands import sim as sim_cmd
from poppy_cli.commands import snap as snap_cmd
from poppy_cli.commands import teleop as teleop_cmd
from poppy_cli.commands import tui as tui_cmd
from poppy_cli.group import PoppyGroup
from poppy_cli.output import (
    EXIT_FAILURE,
    EXIT_INTERRUPTED,
    EXIT_USAGE,
    err_console,
    error_line,
    log_to_stderr,
)

app = typer.Typer(
    name="poppy",
    help="Set up, drive, simulate and serve robots built from Dynamixel servos.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    rich_markup_mode="rich",
    cls=PoppyGroup,  # `--sim [mujoco]`, old flag spellings, help pages: see poppy_cli/group.py
)


# The profiles' meshes are the Poppy project's hardware (profiles/<robot>/meshes/LICENSE).
MESHES_NOTICE = (
    "Robot meshes: Poppy project (poppy-humanoid, poppy-torso, poppy-ergo-jr), CC BY-SA 4.0, "
    "decimated; see profiles/<robot>/meshes/LICENSE"
)


def version_text() -> str:
    """``poppy X.Y.Z``, on a second line what it runs on (from package metadata: nothing is
    imported), and on a third the notice of the robots' meshes it ships."""
    import platform
    from importlib import metadata

    def version_of(package: str) -> str:
        try:
            return metadata.version(package)
        except metadata.PackageNotFoundError:
            return "not installed"

    libraries = ", ".join(
        f"{name} {version_of(name)}" for name in ("typer", "rich", "textual", "numpy", "mujoco")
    )
    return (
        f"poppy {version_of('poppy')}\n"
        f"Python {platform.python_version()} on {platform.system() or 'unknown'}; {libraries}\n"
        f"{MESHES_NOTICE}"
    )


def _show_version(shown: bool) -> None:
    if shown:
        sys.stdout.write(version_text() + "\n")
        raise typer.Exit(0)


@app.callback()
def _root(
    debug: bool = typer.Option(False, "--debug", help="Show tracebacks and debug logs."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help="Show info logs."),
    quiet: bool = typer.Option(
        False, "--quiet", "-q", help="Only errors on stderr: no warnings, notes or progress."
    ),
    _version: bool = typer.Option(
        False,
        "--version",
        "-V",
        is_eager=True,
        callback=_show_version,
        help="Show poppy's version (and Python's, and its main libraries') and exit.",
    ),
) -> None:
    if quiet and (debug or verbose):
        raise typer.BadParameter("it cannot go with --verbose or --debug", param_hint="--quiet")
    state.debug = debug
    err_console.quiet = quiet  # error_line still prints (see poppy_cli.output)
    if quiet:
        import warnings

        logging.getLogger().setLevel(logging.ERROR)
        warnings.simplefilter("ignore")
    if debug or verbose:
        log_to_stderr(
            logging.DEBUG if debug else logging.INFO,
            "%(asctime)s %(name)s %(levelname)s: %(message)s",
        )
    else:
        log_to_stderr()  # warnings, escaped (a motor name may hold terminal escapes)


# `poppy --help` lists the commands in these panels, in this order.
START, SETUP, DRIVE, MOVES, SERVE, SIMULATE = (
    "Start here",
    "Set up",
    "Drive",
    "Moves",
    "Serve",
    "Simulate",
)

app.command("demo", rich_help_panel=START)(demo.demo)
app.command("tui", rich_help_panel=START)(tui_cmd.tui)
app.command("ports", rich_help_panel=SETUP)(ports.ports)
app.command("scan", rich_help_panel=SETUP)(scan.scan)
# motor_setup adds the setup commands to the `poppy motor` group defined in commands/motor.py.
app.add_typer(motor_setup.app, name="motor", rich_help_panel=SETUP)
app.add_typer(config.app, name="config", rich_help_panel=SETUP)
app.command("calibrate", rich_help_panel=SETUP)(calibrate_cmd.calibrate)
app.add_typer(setup_cmd.app, name="setup", rich_help_panel=SETUP)
app.command("doctor", rich_help_panel=SETUP)(doctor.doctor)
# reach_cmd adds `reach` and `where` to the `poppy robot` group defined in commands/robot.py.
app.add_typer(reach_cmd.app, name="robot", rich_help_panel=DRIVE)
app.add_typer(primitive_cmd.app, name="primitive", rich_help_panel=DRIVE)
app.command("teleop", rich_help_panel=DRIVE)(teleop_cmd.teleop)
app.add_typer(camera.app, name="camera", rich_help_panel=DRIVE)
app.command("record", rich_help_panel=MOVES)(record_cmd.record)
app.command("play", rich_help_panel=MOVES)(play_cmd.play)
app.add_typer(moves_cmd.app, name="moves", rich_help_panel=MOVES)
app.add_typer(dataset.app, name="dataset", rich_help_panel=MOVES)
app.command("serve", rich_help_panel=SERVE)(serve_cmd.serve)
app.add_typer(snap_cmd.app, name="snap", rich_help_panel=SERVE)
app.command("notebook", rich_help_panel=SERVE)(notebook_cmd.notebook)
app.add_typer(fleet.app, name="fleet", rich_help_panel=SERVE)
app.add_typer(service_cmd.app, name="service", rich_help_panel=SERVE)
app.command("emulate", rich_help_panel=SIMULATE)(emulate.emulate)
app.add_typer(sim_cmd.app, name="sim", rich_help_panel=SIMULATE)


def usage_line(exc: click.exceptions.UsageError) -> str:
    """A usage error as one line: Click's message and where the help is."""
    message = " ".join(exc.format_message().split())
    where = exc.ctx.command_path if exc.ctx is not None else "poppy"
    return f"{message} (see `{where} --help`)"


def main() -> None:
    """Run the CLI; a PoppyError becomes one line on stderr (one per problem) and exit code 1,
    a usage error one line and exit code 2."""
    from poppy_core.errors import ConfigError, PoppyError

    try:
        code = app(prog_name="poppy", standalone_mode=False)
    except click.exceptions.NoArgsIsHelpError as exc:  # `poppy moves`: the help, as before
        exc.show()
        sys.exit(exc.exit_code)
    except click.exceptions.UsageError as exc:
        error_line(usage_line(exc))
        sys.exit(EXIT_USAGE)
    except click.exceptions.ClickException as exc:  # e.g. a file Click could not open
        error_line(" ".join(exc.format_message().split()))
        sys.exit(exc.exit_code)
    except typer.Abort as exc:  # Ctrl-C or end of input at a prompt
        if isinstance(exc.__context__, KeyboardInterrupt):  # Click keeps what it replaced
            error_line("interrupted")
            sys.exit(EXIT_INTERRUPTED)
        error_line("aborted")
        sys.exit(EXIT_FAILURE)
    except PoppyError as exc:
        if state.debug:
            raise
        problems = exc.problems if isinstance(exc, ConfigError) else [exc]
        for problem in problems:
            error_line(str(problem))
        sys.exit(EXIT_FAILURE)
    except KeyboardInterrupt:
        if state.debug:
            raise
        error_line("interrupted")
        sys.exit(EXIT_INTERRUPTED)
    except Exception as exc:  # a bug: still one line unless --debug
        if state.debug:
            raise
        error_line(f"unexpected {type(exc).__name__}: {exc} (run with --debug for the traceback)")
        sys.exit(EXIT_FAILURE)
    sys.exit(code if isinstance(code, int) else 0)


if __name__ == "__main__":
    main()
