"""``close_all``: every closing step of an owner, whatever fails first."""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable


def close_all(
    steps: Iterable[tuple[str, Callable[[], object]]], log: logging.Logger, whole: str
) -> None:
    """Run every closing step in order whatever fails first; each failure is logged once at
    WARNING (``"closing {whole}: {step} failed: ..."``) and the next step runs.

    A ``KeyboardInterrupt`` or ``SystemExit`` during a step (Ctrl-C twice) is raised again once
    every step ran, so that nothing is left open by it.
    """
    interrupted: BaseException | None = None
    for what, step in steps:
        try:
            step()
        except Exception as exc:
            log.warning("closing %s: %s failed: %s", whole, what, str(exc) or type(exc).__name__)
        except BaseException as exc:
            interrupted = interrupted or exc
    if interrupted is not None:
        raise interrupted
