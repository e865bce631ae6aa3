"""Options and plumbing shared by the study commands: ``bench stribeck``, ``bench rbfnn``,
``reproduce`` and ``report``.

Each option is a function returning a :class:`typer.models.OptionInfo`, used in an
``Annotated`` parameter, so the flag's name and checks are written once and each command
keeps its own help text. :func:`study_progress` is the progress display of the benchmark
commands (a spinner on a terminal, time-stamped lines otherwise) and :func:`print_written`
its closing lines.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

import typer
from rich.markup import escape

from ._app import err_console

__all__ = [
    "out_option",
    "print_written",
    "quick_option",
    "seed_option",
    "study_progress",
]


def out_option(help: str, *, folder: bool = False) -> Any:
    """``--out``/``-o``: the output folder (``folder``: refuse an existing file)."""
    extra = {"file_okay": False} if folder else {}
    return typer.Option("--out", "-o", help=help, **extra)


def quick_option(help: str) -> Any:
    """``--quick``: reduced designs and budgets."""
    return typer.Option("--quick", help=help)


def seed_option(help: str, *, non_negative: bool = False) -> Any:
    """``--seed``: the base seed (``non_negative``: refuse negative seeds)."""
    return typer.Option(help=help, min=0 if non_negative else None)


@contextlib.contextmanager
def study_progress(
    t0: float | None = None, *, quiet: bool = False
) -> Iterator[tuple[Callable[[str], None], Any]]:
    """A progress display on stderr for a long study (:func:`fricid.cli._progress.tracker`).

    Yields ``(progress, status)``: ``progress(message)`` names the stage under way (on a
    terminal, the bar's label; otherwise a line with the seconds since the start, and a line at
    least every 10 s while a stage runs); ``status.update(message)`` does the same for a last
    message such as "writing ...". Nothing with ``quiet`` (the command's ``--quiet``) or
    ``fricid --quiet``. ``t0`` is accepted for the callers' own total time
    (:func:`print_written`).
    """
    from ._progress import tracker

    with tracker("study", None, quiet=quiet) as t:

        def progress(msg: str) -> None:
            t.stage(msg, force=True)

        yield progress, _Status(t)


class _Status:
    """``status.update(message)`` of :func:`study_progress`."""

    def __init__(self, tracker: Any) -> None:
        self._tracker = tracker

    def update(self, message: str) -> None:
        self._tracker.stage(message, force=True)


def print_written(paths: Sequence[Path] | None, t0: float) -> None:
    """On stderr: one ``wrote PATH`` line per file, then the total time since ``t0``."""
    for path in paths or ():
        err_console.print(f"wrote {escape(str(path))}", highlight=False)
    err_console.print(f"done in {time.perf_counter() - t0:.1f} s", highlight=False)
