"""The ``fricid`` command line (argument parsing and printing only).

Importing this package is cheap: the Typer application and its sub-commands load when
:data:`app` is first used or :func:`main` runs, so the console script's interrupt handling
(:func:`fricid.cli._app.main`) covers the imports too.
"""

from __future__ import annotations

import atexit
import sys
from typing import Any

__all__ = ["app", "main"]


#: The exit status of the command this process ran, once it has ended (:func:`main`).
_STATUS: list[int] = []


def _exit_status(code: object) -> int:
    """The process status Python gives ``sys.exit(code)``."""
    if code is None:
        return 0
    return int(code) if isinstance(code, int) else 1


def _end_process() -> None:
    """The first exit hook registered, so the last to run
    (:func:`fricid.cli._app.end_process`)."""
    module = sys.modules.get(f"{__name__}._app")
    if module is not None:
        module.end_process(_STATUS[-1] if _STATUS else None)


def main() -> None:
    """Entry point of the ``fricid`` console script; it ends the process (call
    :func:`fricid.cli._app.main` or use :data:`app` to run a command in a program).

    An interrupt is one line on stderr and status 130 (143 for SIGTERM) wherever it lands,
    from importing the command line to the process's last exit hook
    (:func:`fricid.cli._app.end_process`).
    """
    atexit.register(_end_process)
    try:
        from ._app import main as run
    except KeyboardInterrupt:  # Ctrl-C while the command line itself is imported
        sys.stderr.write("interrupted; no file was written\n")
        sys.exit(130)
    try:
        run(until_exit=True)
    except SystemExit as exc:
        _STATUS.append(_exit_status(exc.code))
        raise
    except KeyboardInterrupt:  # before the handlers were in place
        sys.stderr.write("interrupted; no file was written\n")
        sys.exit(130)


def __getattr__(name: str) -> Any:
    if name == "app":
        from . import _commands  # noqa: F401  (registers the sub-commands)
        from ._app import app

        return app
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
