"""Every command's ``--help`` speaks to a command-line user: no Python module paths or
function names (a new user's trial found ``fricid.io.READERS``, ``check_paths``,
``fricid.identify.dynamic.trajectory`` and others in them)."""

from __future__ import annotations

import re

import typer
from typer.testing import CliRunner

from fricid.cli import app

INTERNAL = re.compile(r"fricid\.[a-z_]+|check_paths|READERS|(?<![>\w])_[a-z]+\(")
#: Jargon a new user's trial found: a library's name, implementation words, typer's Python
#: type placeholders.
JARGON = re.compile(r"lmfit|atomically|escaper|<list\[\w+\]>")
EQUATION = re.compile(r"\beq\. \d")
PAPER = re.compile(r"BAS-\s?RBFNN paper|RWSAVSBAS paper")


def _commands(command, path: list[str]):
    """Every command's path (typer's groups are its own vendored click's, not ``click.Group``:
    a group is what lists commands)."""
    yield path
    if hasattr(command, "list_commands"):
        ctx = type(command).context_class(command)
        for name in command.list_commands(ctx):
            yield from _commands(command.get_command(ctx, name), [*path, name])


def test_every_command_is_visited():
    paths = [" ".join(p) for p in _commands(typer.main.get_command(app), [])]
    assert {"fit", "export", "robot fit", "fleet"} <= set(paths), paths


def _found(pattern: re.Pattern) -> list[str]:
    runner = CliRunner()
    found = []
    for path in _commands(typer.main.get_command(app), []):
        text = " ".join(runner.invoke(app, [*path, "--help"], terminal_width=200).output.split())
        found += [f"{' '.join(path) or 'fricid'}: {m}" for m in pattern.findall(text)]
    return found


def test_no_help_cites_python_internals():
    found = _found(INTERNAL)
    assert not found, found


def test_no_help_speaks_jargon():
    found = _found(JARGON)
    assert not found, found


def test_a_help_that_cites_equations_names_their_paper():
    runner = CliRunner()
    unnamed = []
    for path in _commands(typer.main.get_command(app), []):
        text = " ".join(runner.invoke(app, [*path, "--help"], terminal_width=200).output.split())
        if EQUATION.search(text) and not PAPER.search(text):
            unnamed.append(" ".join(path))
    assert not unnamed, unnamed
