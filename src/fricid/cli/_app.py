"""The ``fricid`` Typer application and its shared plumbing.

Sub-commands live one per module and register themselves on :data:`app`. Results go to
stdout, diagnostics and progress to stderr; a :class:`~fricid.errors.FricidError` becomes one
line on stderr and exit status 2, never a traceback (DESIGN.md, "Errors").
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from functools import wraps
from typing import Any

import typer
from rich.console import Console
from rich.markup import escape

from ..errors import FricidError

__all__ = ["app", "bench_app", "console", "err_console", "handle_errors"]

app = typer.Typer(
    name="fricid",
    help=(
        "Identify the friction of robot joints from constant-velocity sweeps, and hand the "
        "model to a controller.\n\nUnits are SI throughout (rad, rad/s, N m, A, degC, s) "
        "unless a flag says otherwise. Run `fricid COMMAND --help` for each command."
    ),
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)

bench_app = typer.Typer(
    help="Benchmarks of the papers' studies (print tables, write figures).",
    no_args_is_help=True,
)
app.add_typer(bench_app, name="bench")

console = Console()
err_console = Console(stderr=True)


def handle_errors(func: Callable[..., Any]) -> Callable[..., Any]:
    """Turn fricid's own errors into one line on stderr and exit status 2."""

    @wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return func(*args, **kwargs)
        except FricidError as exc:
            err_console.print(
                f"[bold red]error:[/] {escape(str(exc))}", highlight=False, soft_wrap=True
            )
            raise typer.Exit(code=2) from None
        except KeyboardInterrupt:
            err_console.print("interrupted; no partial output was written")
            sys.exit(130)

    return wrapper
