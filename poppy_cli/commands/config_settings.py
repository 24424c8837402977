"""`poppy config set/get/unset/path`: the user's default robot (profile, port), where files live."""

from __future__ import annotations

import typer

from poppy_cli.options import json_option
from poppy_cli.output import EXIT_FAILURE, console, error_line, print_json

KEY_HELP = "Setting: profile (the default robot) or port (its serial port)."
ANY_KEY_HELP = KEY_HELP + " All of them when not given."


def register(app: typer.Typer) -> None:
    """Add the settings commands to the `poppy config` group."""
    app.command("set")(set_cmd)
    app.command("get")(get_cmd)
    app.command("unset")(unset_cmd)
    app.command("path")(path_cmd)


def set_cmd(
    key: str = typer.Argument(..., help=KEY_HELP, metavar="KEY"),
    value: str = typer.Argument(..., help="Its value: a profile name, a port.", metavar="VALUE"),
) -> None:
    """Store a default (profile or port) in the user settings file.

    POPPY_PROFILE/POPPY_PORT and the options still win over it.

    Examples:
        poppy config set profile ergo-jr
        poppy config set port /dev/ttyUSB0
    """
    from dataclasses import replace

    from poppy_cli.settings import check_setting, load_settings, save_settings

    checked = check_setting(key, value)
    written = save_settings(replace(load_settings(), **{key: checked}))
    console.print(f"{key} = {checked} (in {written})")


def get_cmd(
    key: str | None = typer.Argument(None, help=ANY_KEY_HELP, metavar="[KEY]"),
    json_output: bool = json_option("Print a JSON object of the settings."),
) -> None:
    """Print a stored default (exit 1 when unset, as `git config --get`), or all of them.

    Examples:
        poppy config get profile
        poppy config get
    """
    from poppy_cli.settings import SETTINGS_KEYS, check_key, load_settings

    stored = load_settings()
    if key is not None:
        value = getattr(stored, check_key(key))
        if json_output:
            print_json({key: value})
        elif value is None:
            error_line(f"{key} is not set (`poppy config set {key} VALUE`)")
        else:
            console.print(value, markup=False, highlight=False)
        if value is None:
            raise typer.Exit(EXIT_FAILURE)
        return
    values = {name: getattr(stored, name) for name in SETTINGS_KEYS}
    if json_output:
        print_json(values)
        return
    for name, value in values.items():
        if value is not None:
            console.print(f"{name}={value}", markup=False, highlight=False)


def unset_cmd(key: str = typer.Argument(..., help=KEY_HELP, metavar="KEY")) -> None:
    """Remove a stored default.

    Examples:
        poppy config unset port
    """
    from dataclasses import replace

    from poppy_cli.settings import check_key, load_settings, save_settings

    written = save_settings(replace(load_settings(), **{check_key(key): None}))
    console.print(f"{key} unset (in {written})")


def path_cmd(
    profile: str | None = typer.Argument(
        None, help="A profile name: print the file it resolves to.", metavar="[PROFILE]"
    ),
    json_output: bool = json_option("Print a JSON object of the paths."),
) -> None:
    """Print where the user settings and profiles live, or the file PROFILE resolves to.

    A user profile hides an installed one of the same name.

    Examples:
        poppy config path
        poppy config path ergo-jr
    """
    from poppy_cli.settings import settings_file
    from poppy_core.robot.profiles import find_profile, profile_dirs, user_profile_dir

    if profile is not None:
        info = find_profile(profile)
        if json_output:
            print_json({"profile": info.name, "file": str(info.file), "user": info.user})
        else:
            console.print(str(info.file), markup=False, highlight=False)
        return
    paths = {
        "settings": str(settings_file()),
        "user_profiles": str(user_profile_dir()),
        "profile_folders": [str(p) for p in profile_dirs()],
    }
    if json_output:
        print_json(paths)
        return
    console.print(f"settings       {paths['settings']}", markup=False, highlight=False)
    console.print(f"user profiles  {paths['user_profiles']}", markup=False, highlight=False)
    for folder in paths["profile_folders"]:
        console.print(f"profiles from  {folder}", markup=False, highlight=False)
