"""The ``fricid`` Typer application and its shared plumbing.

Sub-commands live one per module and register themselves on :data:`app`. Results go to
stdout, diagnostics and progress to stderr; a :class:`~fricid.errors.FricidError` becomes one
line on stderr and exit status 2, never a traceback (DESIGN.md, "Errors").

Interrupts end the same way wherever they land (importing, parsing, compiling, writing):
one line on stderr and exit status 130 for Ctrl-C (SIGINT), 143 for SIGTERM. SIGTERM is
turned into :class:`Terminated`, a ``KeyboardInterrupt``, so every cleanup path an interrupt
takes runs for it too (temporary files removed, worker pools torn down). An exception chained
from an interrupt, or raised while one is being handled (numba's ``RuntimeError: no compiled
object yet`` after Ctrl-C during compilation), counts as that interrupt. An interrupt that
arrives after the command has finished (while the process shuts down: its pools, threads and
exit hooks) prints the same line and ends the process with the same status, once the exit
hooks have run (:func:`end_process`).
"""

from __future__ import annotations

import contextlib
import os
import re
import signal
import sys
import threading
import warnings
from collections.abc import Callable, Iterator
from functools import wraps
from types import FrameType
from typing import Any

import typer
from rich.console import Console, ConsoleDimensions
from rich.markup import escape

from ..errors import FricidError, FricidWarning

__all__ = [
    "PIPE_WIDTH",
    "Terminated",
    "WideConsole",
    "app",
    "bench_app",
    "console",
    "err_console",
    "handle_errors",
    "interrupt_exit",
    "main",
    "plural",
    "robot_app",
    "signal_handlers",
]


def _argument_type(self, ctx) -> str | None:
    """An argument with a metavar shows it alone, as an option does; typer would add its
    Python type (``LOG <list[Path]>``), which means nothing on a command line."""
    return None if self.metavar is not None else _typer_argument_type(self, ctx)


_typer_argument_type = typer.core.TyperArgument.display_type_rich
typer.core.TyperArgument.display_type_rich = _argument_type

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

robot_app = typer.Typer(
    help=(
        "Whole robots from their URDF: design an excitation, identify every joint's friction "
        "with the arm's rigid-body dynamics, export all joints."
    ),
    no_args_is_help=True,
)
app.add_typer(robot_app, name="robot")

#: Columns of a console whose output is not a terminal (a pipe, a file, CI) and whose width
#: ``COLUMNS`` does not set: wide enough that tables keep whole model names.
PIPE_WIDTH = 160


class WideConsole(Console):
    """A rich console that is :data:`PIPE_WIDTH` columns wide (or its terminal's width, if
    wider) when its output is not a terminal and ``COLUMNS`` is unset, instead of rich's 80:
    tables in a pipe then keep ``coulomb_viscous_asym`` whole instead of ``coulomb_visc…``
    and lines are not broken mid-sentence. On a terminal, or with ``COLUMNS``, it is rich's."""

    @property
    def size(self) -> ConsoleDimensions:
        size = Console.size.fget(self)  # type: ignore[attr-defined]
        if self._width is None and not self.is_terminal and not os.environ.get("COLUMNS"):
            return ConsoleDimensions(max(size.width, PIPE_WIDTH), size.height)
        return size

    @size.setter
    def size(self, new_size: tuple[int, int]) -> None:
        Console.size.fset(self, new_size)  # type: ignore[attr-defined]


#: Neither console turns ``:name:`` into an emoji: joint and parameter names come from files
#: (``joint2:m: ...`` printed as ``joint2Ⓜ ...``), and fricid's own text uses none.
console = WideConsole(emoji=False)
err_console = WideConsole(stderr=True, emoji=False)

#: Exit status of a command stopped by a signal: 128 + the signal number, as a shell reports.
EXIT_INTERRUPTED = 130
EXIT_TERMINATED = 143

#: What every interrupted command can say: outputs are written atomically (fricid.io.atomic).
_DEFAULT_DETAIL = "no file was left half-written"


def plural(n: int, noun: str, many: str | None = None) -> str:
    """``1 joint``, ``3 joints``, ``2 passes`` (``many`` for an irregular plural)."""
    return f"{n} " + (noun if n == 1 else many or f"{noun}s")


class Terminated(KeyboardInterrupt):
    """SIGTERM arrived; raised in the main thread by the handler of :func:`signal_handlers`."""


class _State:
    """The signal seen by the current command (reset when the outermost guard is entered)."""

    depth = 0
    signal: int | None = None
    reported = False
    #: A signal that arrived after the command had finished (:func:`_on_late_signal`).
    late: int | None = None
    unraisable_hook: Any = sys.__unraisablehook__
    #: ``--quiet`` given to ``fricid`` itself: no progress display (:mod:`fricid.cli._progress`).
    quiet = False


def set_quiet(quiet: bool) -> None:
    """Turn progress off (``True``) or back on for the current command."""
    _State.quiet = bool(quiet)


def is_quiet() -> bool:
    """Whether progress is off (``--quiet``)."""
    return _State.quiet


def _on_signal(signum: int, frame: FrameType | None) -> None:
    _State.signal = signum
    if signum == signal.SIGTERM:
        raise Terminated("terminated")
    raise KeyboardInterrupt


def _interrupt_line(signum: int) -> tuple[int, str]:
    if signum == signal.SIGTERM:
        return EXIT_TERMINATED, f"terminated (SIGTERM); {_DEFAULT_DETAIL}"
    return EXIT_INTERRUPTED, f"interrupted; {_DEFAULT_DETAIL}"


def _on_late_signal(signum: int, frame: FrameType | None) -> None:
    """SIGINT or SIGTERM after the command finished: say so in one line now, and end with
    its status once the exit hooks have run (:func:`end_process`); raising here would
    interrupt those hooks (pools shutting down, temporary files removed)."""
    _State.signal = _State.late = signum
    if not _State.reported:
        _State.reported = True
        with contextlib.suppress(Exception):
            sys.stdout.flush()
        with contextlib.suppress(Exception):
            sys.stderr.write(_interrupt_line(signum)[1] + "\n")
            sys.stderr.flush()


def end_process(status: int | None) -> None:
    """End the console script's process once its exit hooks have run.

    Parameters
    ----------
    status : int or None
        The command's exit status (None: unknown, an exception escaped).

    Notes
    -----
    The console script registers this as its first exit hook, so it runs after every other
    one (they run in reverse order): pools are shut down, temporary files removed. If
    SIGINT or SIGTERM arrived after the command finished (:func:`_on_late_signal` said so
    in one line), the process ends with status 130 or 143. Otherwise it ends with the
    command's status at once, without the interpreter's teardown (freeing modules, a good
    part of a second after a fleet run): during that teardown Python runs no signal handler
    and puts the default action back, so a Ctrl-C there would kill the process without a
    word. With an unknown status the teardown runs as usual, both signals ignored; where
    the command did not own the signals (not in the main thread, or ignored from the
    start), nothing changes.
    """
    ours = [s for s in (signal.SIGINT, signal.SIGTERM) if signal.getsignal(s) is _on_late_signal]
    for signum in ours:
        signal.signal(signum, signal.SIG_IGN)  # (runs a pending handler first)
    if _State.late is not None:
        status = _interrupt_line(_State.late)[0]
    elif not ours or status is None:
        return
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    os._exit(status)


def _on_alarm(signum: int, frame: FrameType | None) -> None:
    """Raise again an interrupt that was swallowed (see :func:`_on_unraisable`)."""
    if _State.signal is not None:
        _on_signal(_State.signal, frame)


def _on_unraisable(unraisable: Any) -> None:
    """An interrupt raised where Python cannot propagate it (a ctypes callback: numba's LLVM
    compiling calls back into Python) is printed as "Exception ignored" and lost, and the
    command would run on as if never interrupted. Raise it again 50 ms later instead, and
    again for as long as it keeps landing in such a callback. Anything else goes to the
    previous hook."""
    if isinstance(unraisable.exc_value, KeyboardInterrupt) and _State.signal is not None:
        signal.setitimer(signal.ITIMER_REAL, 0.05)
        return
    _State.unraisable_hook(unraisable)


@contextlib.contextmanager
def _signals_blocked() -> Iterator[None]:
    """SIGINT and SIGTERM held back (delivered at the end) while handlers are changed."""
    if not hasattr(signal, "pthread_sigmask"):  # pragma: no cover - not POSIX
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


@contextlib.contextmanager
def signal_handlers(*, until_exit: bool = False) -> Iterator[None]:
    """SIGINT and SIGTERM raise (``KeyboardInterrupt``, :class:`Terminated`) for the body.

    Only in the main thread (the only one that may set handlers), and not for a signal that
    is ignored (``nohup``, a background job): that stays ignored. The previous handlers are
    restored after the body; with ``until_exit`` (the console script, for the rest of the
    process) a signal after the body is reported in one line instead
    (:func:`end_process`). Signals are held back while the handlers change.
    """
    outer = _State.depth == 0
    if outer:
        _State.signal, _State.reported, _State.late = None, False, None
    _State.depth += 1
    previous: dict[int, Any] = {}
    main_thread = threading.current_thread() is threading.main_thread()
    try:
        if main_thread:
            with _signals_blocked():
                for signum in (signal.SIGINT, signal.SIGTERM):
                    old = signal.getsignal(signum)
                    if old is not signal.SIG_IGN:
                        previous[signum] = old
                        signal.signal(signum, _on_signal)
                if outer and previous:
                    previous[signal.SIGALRM] = signal.signal(signal.SIGALRM, _on_alarm)
                    _State.unraisable_hook = sys.unraisablehook
                    sys.unraisablehook = _on_unraisable
        yield
    finally:
        with _signals_blocked() if main_thread else contextlib.nullcontext():
            _State.depth -= 1
            if signal.SIGALRM in previous:
                signal.setitimer(signal.ITIMER_REAL, 0)
                sys.unraisablehook = _State.unraisable_hook
            for signum, old in previous.items():
                if until_exit and outer and signum != signal.SIGALRM:
                    old = _on_late_signal
                signal.signal(signum, old if old is not None else signal.SIG_DFL)


def _chain(exc: BaseException) -> Iterator[BaseException]:
    seen: set[int] = set()
    todo: list[BaseException] = [exc]
    while todo:
        item = todo.pop(0)
        if id(item) in seen:
            continue
        seen.add(id(item))
        yield item
        todo.extend(e for e in (item.__cause__, item.__context__) if e is not None)


def interrupt_exit(exc: BaseException) -> tuple[int, str] | None:
    """The exit status and the line to print if ``exc`` ends an interrupted command.

    Parameters
    ----------
    exc : BaseException
        What the command raised.

    Returns
    -------
    (int, str) or None
        ``(130, "interrupted; ...")`` or ``(143, "terminated (SIGTERM); ...")`` when ``exc``
        is a ``KeyboardInterrupt``, has one in its chain (``__cause__``, ``__context__``), or
        is an ``Exception`` raised after SIGINT or SIGTERM arrived; None otherwise. The
        detail after the semicolon is the message of an interrupt in the chain that has
        one (a fleet says what it kept and how to resume), else that no file was left
        half-written.
    """
    chain = list(_chain(exc))
    interrupts = [e for e in chain if isinstance(e, KeyboardInterrupt)]
    if not interrupts and not (_State.signal is not None and isinstance(exc, Exception)):
        return None
    terminated = _State.signal == signal.SIGTERM or any(
        isinstance(e, Terminated) for e in interrupts
    )
    details = [str(e) for e in interrupts if not isinstance(e, Terminated) and str(e).strip()]
    detail = " ".join(details[0].split()) if details else _DEFAULT_DETAIL
    if terminated:
        return EXIT_TERMINATED, f"terminated (SIGTERM); {detail}"
    return EXIT_INTERRUPTED, f"interrupted; {detail}"


def _report_interrupt(code: int, line: str) -> None:
    if not _State.reported:
        _State.reported = True
        with contextlib.suppress(Exception):
            err_console.print(escape(line), highlight=False, soft_wrap=True)
    sys.exit(code)


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """``warnings.showwarning`` for the CLI: one line on stderr, no source line."""
    text = " ".join(str(message).split())
    if issubclass(category, FricidWarning):
        words = re.findall(r"[A-Z][a-z0-9]*", category.__name__.removesuffix("Warning"))
        label = " ".join(words).lower()
        label = "warning" if label in ("", "fricid") else label
        line_out = f"[bold yellow]warning ({label}):[/] {escape(text)}"
    else:
        line_out = f"[bold yellow]warning:[/] {escape(text)} ({category.__name__})"
    with contextlib.suppress(Exception):
        err_console.print(line_out, highlight=False, soft_wrap=True)


@contextlib.contextmanager
def one_line_warnings() -> Iterator[None]:
    """Show every warning raised during a command as one line on stderr (DESIGN.md, "Errors").

    Only the display changes: which warnings are shown (the warning filters) stays as Python,
    ``-W`` or the test runner set it.
    """
    with warnings.catch_warnings():
        warnings.showwarning = _show_warning
        yield


def handle_errors(func: Callable[..., Any]) -> Callable[..., Any]:
    """Turn fricid's own errors into one line on stderr and exit status 2, and an interrupt
    (anywhere in the command) into one line and exit status 130 or 143."""

    @wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with signal_handlers(), one_line_warnings():
            try:
                return func(*args, **kwargs)
            except BaseException as exc:
                stop = interrupt_exit(exc)
                if stop is not None:
                    _report_interrupt(*stop)
                if isinstance(exc, FricidError):
                    err_console.print(
                        f"[bold red]error:[/] {escape(str(exc))}", highlight=False, soft_wrap=True
                    )
                    raise typer.Exit(code=2) from None
                raise

    return wrapper


def main(args: list[str] | None = None, *, until_exit: bool = False) -> None:
    """Run the ``fricid`` command line (the console script's entry, via :mod:`fricid.cli`).

    Everything runs under :func:`signal_handlers`, from importing the sub-commands to the
    exit, so an interrupt that lands outside a command (while importing, while the
    arguments are parsed, or while the handlers are put back) also ends in one line and
    status 130 or 143. ``until_exit``: the process ends with this call (the console script),
    and a signal after the command is reported too (:func:`end_process`).
    """
    try:
        with signal_handlers(until_exit=until_exit):
            try:
                from . import _commands  # noqa: F401  (registers the sub-commands)

                app(args=args)
            except SystemExit as exc:
                # typer turns a KeyboardInterrupt outside a command into a silent exit 130
                if exc.code in (EXIT_INTERRUPTED, EXIT_TERMINATED) and _State.signal is not None:
                    code = EXIT_TERMINATED if _State.signal == signal.SIGTERM else EXIT_INTERRUPTED
                    _report_interrupt(*(interrupt_exit(exc) or (code, "interrupted")))
                raise
    except SystemExit:
        raise
    except BaseException as exc:  # an interrupt anywhere above, while it was reported too
        stop = interrupt_exit(exc)
        if stop is None:
            raise
        _report_interrupt(*stop)


def _restore_source_date(previous: str | None) -> None:
    if previous is None:
        os.environ.pop("SOURCE_DATE_EPOCH", None)
    else:
        os.environ["SOURCE_DATE_EPOCH"] = previous


@app.callback()
def _root(
    ctx: typer.Context,
    reproducible: bool = typer.Option(
        False,
        "--reproducible",
        help=(
            "Byte-identical output files for identical inputs: stamp files with "
            "SOURCE_DATE_EPOCH (seconds since 1970 UTC) when it is set, else with "
            "1970-01-01T00:00:00+00:00, instead of the current time. Setting "
            "SOURCE_DATE_EPOCH alone has the same effect."
        ),
    ),
    quiet: bool = typer.Option(
        False,
        "--quiet",
        "-q",
        help=(
            "No progress display on stderr for any command (as each long command's own "
            "--quiet); results, warnings and errors still print."
        ),
    ),
    delimiter: str | None = typer.Option(
        None,
        "--delimiter",
        help="Field delimiter of every CSV file read: ',', ';' or tab (also: comma, "
        "semicolon, tab). Default: detected from each file's header and first data line.",
    ),
    decimal: str | None = typer.Option(
        None,
        "--decimal",
        help="Decimal mark of every CSV file read: '.' or ',' (with --delimiter ';' or tab). "
        "Default: detected (a decimal comma when the data are written 0,25 and never 0.25).",
    ),
) -> None:
    """Identify the friction of robot joints."""
    set_quiet(quiet)
    if delimiter is not None or decimal is not None:
        from ..io import csv_dialect

        try:
            ctx.with_resource(csv_dialect(delimiter, decimal))
        except FricidError as exc:
            err_console.print(f"[bold red]error:[/] {escape(str(exc))}", highlight=False)
            raise typer.Exit(code=2) from None
    if reproducible and not os.environ.get("SOURCE_DATE_EPOCH", "").strip():
        previous = os.environ.get("SOURCE_DATE_EPOCH")
        os.environ["SOURCE_DATE_EPOCH"] = "0"  # read by fricid.io.atomic.created_timestamp
        ctx.call_on_close(lambda: _restore_source_date(previous))
