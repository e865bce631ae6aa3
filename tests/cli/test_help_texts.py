"""Every command's ``--help`` speaks to a command-line user: no Python module paths or
function names (a new user's trial found ``fricid.io.READERS``, ``check_paths``,
``fricid.identify.dynamic.trajectory`` and others in them)."""

from __future__ import annotations

import re

import click
import typer
from typer.testing import CliRunner

from fricid.cli import app

INTERNAL = re.compile(r"fricid\.[a-z_]+|check_paths|READERS|\b_[a-z]+\(")


def _commands(command: click.Command, path: list[str]):
    yield path
    if isinstance(command, click.Group):
        for name, sub in command.commands.items():
            yield from _commands(sub, [*path, name])


def test_no_help_cites_python_internals():
    runner = CliRunner()
    found = []
    for path in _commands(typer.main.get_command(app), []):
        text = runner.invoke(app, [*path, "--help"], terminal_width=200).output
        found += [f"{' '.join(path) or 'fricid'}: {m}" for m in INTERNAL.findall(text)]
    assert not found, found
