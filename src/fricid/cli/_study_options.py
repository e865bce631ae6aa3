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
def study_progress(t0: float | None = None) -> Iterator[tuple[Callable[[str], None], Any]]:
    """A progress display on stderr for a long study.

    Yields ``(progress, status)``: ``progress(message)`` updates the spinner and, when stderr
    is not a terminal, prints the message with the seconds since ``t0`` (default: now);
    ``status`` is the rich status, for a last message such as "writing ...".
    """
    start = time.perf_counter() if t0 is None else t0
    with err_console.status("starting", spinner="dots") as status:

        def progress(msg: str) -> None:
            status.update(escape(msg))
            if not err_console.is_terminal:
                err_console.print(
                    f"[{time.perf_counter() - start:6.1f} s] {escape(msg)}", highlight=False
                )

        yield progress, status


def print_written(paths: Sequence[Path] | None, t0: float) -> None:
    """On stderr: one ``wrote PATH`` line per file, then the total time since ``t0``."""
    for path in paths or ():
        err_console.print(f"wrote {escape(str(path))}", highlight=False)
    err_console.print(f"done in {time.perf_counter() - t0:.1f} s", highlight=False)
