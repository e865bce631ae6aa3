"""Numbers that tell the truth: every measured number and every example output in the README
comes from a benchmark's JSON output committed in ``benchmarks/results/``, rendered by
``benchmarks/readme_numbers.py``, and no number is typed in the README's prose; ``--help``
carries no typed measurement either, and the sizes it states are the code's.

When one fails after a change: ``python benchmarks/bench_readme.py`` (measure again), then
``python benchmarks/readme_numbers.py --write`` (update the README).
"""

from __future__ import annotations

import importlib.util
import re
import sys

import pytest
from typer.testing import CliRunner

from _docs_workspace import LEADSCREW
from _paths import REPO
from fricid.cli import app

README = REPO / "README.md"
runner = CliRunner()
FIX = "run `python benchmarks/bench_readme.py` then `python benchmarks/readme_numbers.py --write`"

#: Digits the README's prose may hold that are no measurement: names (ROS 2, ros2_control),
#: references into the papers, and the CLI's documented exit status.
ALLOWED = re.compile(
    r"\bros2_control\b|\bROS 2\b|\b(?:Table|Fig\.|eqs?\.|section) \d+(?:-\d+)?\b"
    r"|\bexit status [012]\b"
)


@pytest.fixture(scope="module")
def numbers():
    """``benchmarks/readme_numbers.py``."""
    path = REPO / "benchmarks" / "readme_numbers.py"
    spec = importlib.util.spec_from_file_location("readme_numbers", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def test_readme_numbers_come_from_the_benchmarks_results(numbers):
    text = README.read_text(encoding="utf-8")
    assert numbers.render(text) == text, f"README.md differs from benchmarks/results/: {FIX}"
    names, blocks = numbers.marked(text)
    assert {"demo_wall", "quickstart_fit_wall"} <= set(names) and blocks == ["quickstart"]
    assert set(names) <= set(numbers.NUMBERS)
    # the placeholder for a fresh clone's `make demo` is marked, to be plugged in
    assert "make_demo_fresh" in names


def test_readme_prose_holds_no_typed_number(numbers):
    prose = ALLOWED.sub("", numbers.unmarked(README.read_text(encoding="utf-8")))
    typed = [m.group(0) for m in re.finditer(r".{0,30}\d.{0,20}", prose)]
    assert not typed, f"numbers typed in the README (generate them, or leave them out): {typed}"


def test_readme_opens_with_quick_start_and_its_picture_is_committed():
    text = README.read_text(encoding="utf-8")
    headings = re.findall(r"^## (.+)$", text, re.M)
    assert headings[0] == "Quick start", headings
    intro = text.split("## ")[0].strip().splitlines()
    assert len([line for line in intro if line and not line.startswith("#")]) == 3, intro
    pictures = re.findall(r"!\[[^\]]+\]\(([^)]+\.png)\)", text)
    assert pictures and all((REPO / p).is_file() for p in pictures), pictures
    assert all((REPO / p).stat().st_size < 400_000 for p in pictures)  # small
    for link in re.findall(r"\]\((docs/[^)#]+)", text):  # links into the site's pages
        assert (REPO / link).is_file(), link


def test_readme_layout_names_every_package_as_it_is():
    text = README.read_text(encoding="utf-8")
    layout = text.split("## Layout", 1)[1].split("Beside them")[0]
    src = REPO / "src" / "fricid"
    public = {p.name + "/" for p in src.iterdir() if (p / "__init__.py").is_file()}
    public |= {p.name for p in src.glob("*.py") if not p.name.startswith("_")}
    named = set(re.findall(r"`([\w]+(?:/|\.py))`", layout))
    assert public - {"schemas/"} <= named, public - named
    assert named <= public | {"static/", "learned/", "dynamic/", "studies/"}, named - public


def test_fit_excerpt_keeps_the_sections_shown(numbers):
    out = (
        "[[Model]]\n    m\n[[Variables]]\n    a: 1\n[[Correlations]] (some)\n    C\n"
        "[[Goodness of fit]]\n    G\n[[Trust]]\n    T\n"
    )
    assert numbers.fit_excerpt(out) == [
        "...",
        "[[Variables]]",
        "    a: 1",
        "...",
        "[[Goodness of fit]]",
        "    G",
        "[[Trust]]",
        "    T",
    ]


@pytest.mark.slow
def test_quickstart_output_is_what_fricid_prints(numbers, tmp_path, monkeypatch):
    """The committed output of the README's real-data example is what the commands print now
    (the lines the README shows)."""
    if not LEADSCREW.is_dir():
        pytest.skip(f"real recordings not found at {LEADSCREW}")
    monkeypatch.chdir(tmp_path)
    for run in numbers.load("quickstart.json")["commands"]:
        args = run["command"].split()[1:]
        args = [str(LEADSCREW) if a.endswith("data/real/epos-leadscrew") else a for a in args]
        res = runner.invoke(app, ["--quiet", *args])
        assert res.exit_code == 0, res.output
        if " fit " in run["command"]:
            assert numbers.fit_excerpt(res.stdout) == numbers.fit_excerpt(run["stdout"]), FIX
        else:
            assert res.stdout == run["stdout"], FIX


# --------------------------------------------------------------------------------- --help


def _helps() -> dict[str, str]:
    from typer.main import get_command

    group = get_command(app)
    out = {}
    for name, cmd in group.commands.items():
        subs = getattr(cmd, "commands", None)
        for words in [[name, sub] for sub in subs] if subs else [[name]]:
            out[" ".join(words)] = runner.invoke(app, [*words, "--help"]).output
    return out


@pytest.mark.slow  # every command's --help: seconds
def test_help_states_no_typed_measurement():
    """No --help states a measured time: the only durations are the progress display's own
    cadence, which fricid.cli._progress defines."""
    from fricid.cli import _progress

    cadence = {
        f"{_progress.GRACE_S:g} s",
        f"{3 * _progress.HEARTBEAT_S:g} s",
        f"{_progress.HEARTBEAT_S:g} s",
    }
    for command, text in _helps().items():
        flat = " ".join(text.split())
        for m in re.finditer(r"\b\d+(?:\.\d+)? ?(?:s|min|minutes|seconds|GB|MB)\b", flat):
            assert m.group(0) in cadence, f"fricid {command} --help: {flat[m.start() - 60 :]}"


def test_simulate_help_states_the_designs_size():
    from fricid.cli.simulate import PAPER1_FULL_MILLIONS
    from fricid.sim import preset

    n = preset("paper1", "full").design.n_samples()
    assert round(n / 1e6) == PAPER1_FULL_MILLIONS
    flat = " ".join(runner.invoke(app, ["simulate", "--help"]).output.split())
    assert f"paper1 is about {round(n / 1e6)} million samples" in flat
