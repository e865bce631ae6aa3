"""The ``fricid`` command line (argument parsing and printing only).

Importing this package is cheap: the Typer application and its sub-commands load when
:data:`app` is first used or :func:`main` runs, so the console script's interrupt handling
(:func:`fricid.cli._app.main`) covers the imports too.
"""

from __future__ import annotations

import sys
from typing import Any

__all__ = ["app", "main"]


def main() -> None:
    """Entry point of the ``fricid`` console script."""
    try:
        from ._app import main as run
    except KeyboardInterrupt:  # Ctrl-C while the command line itself is imported
        sys.stderr.write("interrupted; no file was written\n")
        sys.exit(130)
    run()


def __getattr__(name: str) -> Any:
    if name == "app":
        from . import _commands  # noqa: F401  (registers the sub-commands)
        from ._app import app

        return app
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
