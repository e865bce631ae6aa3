"""Docs that cannot rot (issue 17): every ``fricid`` command in the README and every example in
``--help`` is run here, on small data, and the manifest's documentation matches its schema.

Each README command is one test, run as written in a folder holding the files it names
(built once, small: the quick presets, a few runs of a bag; ``tests/_docs_workspace.py``).
Where running as written would take minutes, :data:`SMALLER` lists the arguments added to make
it small (a smaller preset, a budget), and :data:`PARSE_ONLY` the commands that are only parsed
here (every option must exist) because another test runs them at a small size; both say why.
A README command that is in neither and cannot run fails: nothing is skipped silently. The
documentation site's code blocks are run the same way by ``test_docs_site.py``.
"""

from __future__ import annotations

import re
import shlex

import pytest
from typer.testing import CliRunner

from _docs_workspace import (
    LEADSCREW,
    NEEDS_REAL,
    PARSE_ONLY,
    SMALLER,
    command_args,
    site_commands,
)
from _paths import REPO
from fricid.cli import app

ROOT = REPO
README = ROOT / "README.md"
MANIFEST_DOC = ROOT / "docs" / "manifest.md"

runner = CliRunner()


def readme_commands() -> list[str]:
    """Every ``fricid ...`` command in the README's ``sh`` blocks, continuation lines joined,
    comments dropped."""
    text = README.read_text(encoding="utf-8")
    out = []
    for block in re.findall(r"```sh\n(.*?)```", text, re.S):
        for line in block.replace("\\\n", " ").splitlines():
            words = shlex.split(line, comments=True)
            if words and words[0] == "fricid":
                out.append(shlex.join(words))
    return out


def help_examples() -> list[str]:
    """The examples ``fricid extract --help`` shows, one per format (``READER_EXAMPLES``),
    without their parenthesised remarks."""
    from fricid.io.registry import READER_EXAMPLES

    return [re.sub(r"\s+\(.*\)$", "", ex).strip() for ex in READER_EXAMPLES.values()]


def test_every_readme_command_is_run_or_parsed():
    cmds = readme_commands()
    assert len(cmds) >= 30, cmds
    documented = set(cmds) | set(site_commands())  # no stale entries
    assert set(SMALLER) <= documented, set(SMALLER) - documented
    assert set(PARSE_ONLY) <= documented, set(PARSE_ONLY) - documented


@pytest.mark.slow
@pytest.mark.parametrize("command", list(dict.fromkeys(readme_commands() + help_examples())))
def test_documented_command_runs(command, docs_workspace, monkeypatch, tmp_path):
    if any(name in command for name in NEEDS_REAL) and not LEADSCREW.is_dir():
        pytest.skip(f"real recordings not found at {LEADSCREW} (the command reads them)")
    # a fresh folder: one command's output is not another's input
    for item in docs_workspace.iterdir():
        (tmp_path / item.name).symlink_to(item, target_is_directory=item.is_dir())
    monkeypatch.chdir(tmp_path)
    args = command_args(command, LEADSCREW)
    if command in PARSE_ONLY:
        res = runner.invoke(app, [*args, "--help"])
        assert res.exit_code == 0, f"{command}: {res.output}"
        return
    res = runner.invoke(app, ["--quiet", *args])
    assert res.exit_code == 0, f"{command}: exit {res.exit_code}\n{res.output}"
    assert "Traceback" not in res.output


def test_every_command_has_help():
    from typer.main import get_command

    group = get_command(app)
    names = []
    for name, cmd in group.commands.items():
        subs = getattr(cmd, "commands", None)
        names += [[name, sub] for sub in subs] if subs else [[name]]
    assert len(names) >= 12
    for words in names:
        res = runner.invoke(app, [*words, "--help"])
        assert res.exit_code == 0 and "Usage:" in res.output, words


# ------------------------------------------------------------------ the manifest's documentation


def manifest_columns() -> str:
    """The column table of docs/manifest.md, generated from the manifest's JSON Schema."""
    from fricid.fleet.manifest import FIELDS
    from fricid.units import SI_UNITS, UNITS

    rows = ["| column | group | unit in the label | cell | meaning |", "|---|---|---|---|---|"]
    for name, f in FIELDS.items():
        unit = (
            f"{f.quantity}: {', '.join(UNITS[f.quantity])} (none: {SI_UNITS[f.quantity]})"
            if f.quantity
            else ""
        )
        cell = f.text or ("one of " + ", ".join(f.choices) if f.choices else "text")
        help_ = f.help.replace("|", "\\|")
        rows.append(f"| `{name}` | {f.group} | {unit} | {cell} | {help_} |")
    return "\n".join(rows)


def test_manifest_doc_lists_every_column_of_the_schema():
    text = MANIFEST_DOC.read_text(encoding="utf-8")
    m = re.search(r"<!-- columns:begin[^>]*-->\n(.*?)\n<!-- columns:end -->", text, re.S)
    assert m, "docs/manifest.md lost its generated column table"
    assert m.group(1) == manifest_columns(), (
        "docs/manifest.md's column table differs from the schema; replace it with:\n"
        + manifest_columns()
    )
    assert "docs/manifest.md" in README.read_text(encoding="utf-8")
    assert "docs/manifest.md" in runner.invoke(app, ["fleet", "--help"]).stdout


def test_manifest_doc_examples_are_valid_manifests(tmp_path):
    from fricid.fleet import read_manifest

    text = MANIFEST_DOC.read_text(encoding="utf-8")
    csv_text = re.search(r"```csv\n(.*?)```", text, re.S).group(1)
    yaml_text = re.search(r"```yaml\n(.*?)```", text, re.S).group(1)
    (tmp_path / "m.csv").write_text(csv_text)
    (tmp_path / "m.yaml").write_text(yaml_text)
    csv_spec = read_manifest(tmp_path / "m.csv")
    yaml_spec = read_manifest(tmp_path / "m.yaml")
    assert len(csv_spec) == 3 and len(yaml_spec) == 2
