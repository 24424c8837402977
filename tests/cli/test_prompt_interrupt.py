"""Ctrl-C at a prompt is an interruption (exit 130), end of input there an abort (exit 1)."""

from __future__ import annotations

from typing import Any, NoReturn

import pytest
import typer

import poppy_cli.main as cli_main


def _prompt_failing_with(error: BaseException) -> Any:
    def app(**_: Any) -> NoReturn:
        # what typer's prompts do on KeyboardInterrupt or EOFError
        try:
            raise error
        except (KeyboardInterrupt, EOFError):
            raise typer.Abort() from None

    return app


@pytest.mark.parametrize(
    ("error", "code", "line"),
    [(KeyboardInterrupt(), 130, "interrupted"), (EOFError(), 1, "aborted")],
)
def test_ctrl_c_at_a_prompt_exits_130(
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    error: BaseException,
    code: int,
    line: str,
) -> None:
    monkeypatch.setattr(cli_main, "app", _prompt_failing_with(error))
    with pytest.raises(SystemExit) as exited:
        cli_main.main()
    assert exited.value.code == code
    assert line in capsys.readouterr().err
