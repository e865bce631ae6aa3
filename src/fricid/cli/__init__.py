"""The ``fricid`` command line (argument parsing and printing only)."""

from __future__ import annotations

from . import _commands  # noqa: F401  (registers the sub-commands)
from ._app import app

__all__ = ["app", "main"]


def main() -> None:
    """Entry point of the ``fricid`` console script."""
    app()
