"""Progress and the numbers a user reads (issue 17, "Progress and feedback").

CliRunner's streams are not terminals, so every run here is the piped mode: plain lines on
stderr with the elapsed time and an estimate. The grace before the first line
(``_progress.GRACE_S``, 2 s) is set to 0 so that quick runs show their lines.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import _estimate, _progress, app
from fricid.cli._app import PIPE_WIDTH
from fricid.cli.evaluate import metric_row

runner = CliRunner()

#: A plain progress line: ``[   1.2 s] label: ...``.
LINE = re.compile(r"^\[\s*\d+\.\d s\] ")


def run(*args):
    return runner.invoke(app, [str(a) for a in args])


@pytest.fixture
def no_grace(monkeypatch):
    monkeypatch.setattr(_progress, "GRACE_S", 0.0)
    monkeypatch.setattr(_progress, "MIN_GAP_S", 0.0)
    monkeypatch.setattr(_estimate, "MIN_SPAN_S", 0.0)  # quick runs: an estimate all the same


def progress_lines(stderr: str) -> list[str]:
    return [ln for ln in stderr.splitlines() if LINE.match(ln)]


@pytest.fixture(scope="module")
def samples_csv(tmp_path_factory):
    """Stribeck-like samples, both directions (fits in well under a second with lm)."""
    v = np.geomspace(0.01, 1.0, 8)
    v = np.concatenate([v, -v])
    f = np.sign(v) * (0.1 + 0.05 * np.exp(-((v / 0.05) ** 2))) + 0.02 * v
    f = f + 1e-4 * np.random.default_rng(0).standard_normal(v.size)
    path = tmp_path_factory.mktemp("progress") / "s.csv"
    rows = "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(v, f, strict=True))
    path.write_text("velocity [rad/s],friction [N m]\n" + rows)
    return path


def test_simulate_piped_prints_lines_with_elapsed_time_and_estimate(no_grace, tmp_path):
    res = run("simulate", "--preset", "paper2", "--size", "quick", "--out", tmp_path / "l.parquet")
    assert res.exit_code == 0, res.output
    lines = progress_lines(res.stderr)
    assert lines, res.stderr
    assert any("simulating paper2 (quick)" in ln and "%" in ln for ln in lines), lines
    assert any(" left" in ln for ln in lines), lines  # an estimate of the time left
    assert lines[-1].endswith("velocity-temperature runs)") and ": done (" in lines[-1]
    assert res.stdout == ""  # progress never goes to stdout


def test_extract_counts_chunks_of_a_parquet_log(no_grace, tmp_path):
    import pyarrow.parquet as pq

    log = tmp_path / "l.parquet"
    assert run("simulate", "--preset", "paper2", "--size", "quick", "--out", log).exit_code == 0
    n = -(-pq.ParquetFile(log).metadata.num_rows // 20_000)
    res = run("extract", log, "--out", tmp_path / "s.csv", "--chunk-rows", "20000")
    assert res.exit_code == 0, res.output
    lines = progress_lines(res.stderr)
    assert any(f"/{n} chunks read (" in ln for ln in lines), lines
    assert lines[-1].endswith(f"extracting l.parquet: done ({n}/{n} chunks read)"), lines


@pytest.mark.parametrize("where", ["command", "root"])
def test_quiet_turns_progress_off(no_grace, tmp_path, where):
    args = ["simulate", "--preset", "paper2", "--size", "quick", "--out", tmp_path / "l.parquet"]
    args = [*args, "--quiet"] if where == "command" else ["--quiet", *args]
    res = run(*args)
    assert res.exit_code == 0, res.output
    assert progress_lines(res.stderr) == [], res.stderr
    assert "wrote" in res.stderr  # results and closing lines still print
    res = run("simulate", "--preset", "paper2", "--size", "quick", "--out", tmp_path / "m.parquet")
    assert progress_lines(res.stderr), "--quiet must not outlive its command"


def test_quick_steps_print_nothing_when_piped(tmp_path, samples_csv, monkeypatch):
    """A step that ends within the grace (2 s; here made long, so that a loaded machine
    cannot outlast it) prints no progress: scripts stay clean."""
    monkeypatch.setattr(_progress, "GRACE_S", 600.0)
    res = run("fit", samples_csv, "--model", "coulomb_viscous", "--out", tmp_path / "m.json")
    assert res.exit_code == 0, res.output
    assert progress_lines(res.stderr) == [], res.stderr


@pytest.mark.slow  # 1.1 s, quiet machine (the default run kept under 3 minutes)
def test_fit_population_method_counts_evaluations(no_grace, tmp_path, samples_csv):
    res = run(
        "fit", samples_csv, "--model", "stribeck", "--fix", "delta=1", "--method", "vsbas",
        "--max-evals", "3000", "--out", tmp_path / "m.json",
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    lines = progress_lines(res.stderr)
    counts = [ln for ln in lines if "/3,000 evaluations" in ln]
    assert counts and "fitting stribeck (vsbas)" in counts[0], lines
    assert any("budget spent; certifying convergence" in ln for ln in lines), lines
    assert any("3,000/3,000 evaluations (100 %)" in ln for ln in lines), lines
    # then the trust verdict's own step (its leave-one-velocity-out), and the end
    assert any("assessing trust in stribeck" in ln for ln in lines), lines
    assert lines[-1].endswith("done"), lines


def test_fit_without_callback_still_says_it_runs(no_grace, tmp_path, samples_csv):
    """--validate refits per fold: a new stage line, no count from the first stage."""
    res = run(
        "fit", samples_csv, "--model", "coulomb_viscous", "--validate", "lovo",
        "--out", tmp_path / "m.json",
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    lines = progress_lines(res.stderr)
    assert any("validating coulomb_viscous (lovo)" in ln for ln in lines), lines


def test_tracker_estimate_and_lines(no_grace, capsys):
    with _progress.tracker("work", 10, unit="items") as t:
        assert t.mode == "plain"
        t.update(4)
        assert t.estimate() is None  # one report: no rate yet (tests/cli/test_estimate.py)
        assert t.line() == "work: 4/10 items (40 %)"
        t.update(10)
        assert "left" not in t.line()
    err = capsys.readouterr().err
    assert "work: done (10/10 items)" in err
    with _progress.tracker("open-ended", None, unit="chunks read") as t:
        assert t.line() == "open-ended"
        t.advance()
        assert t.line() == "open-ended: 1 chunks read so far"
    assert _progress._seconds(125) == "2 min 5 s" and _progress._seconds(4000) == "1 h 6 min"


def test_fit_budget_is_the_method_s_own_end():
    """A scheduled method (BAS family, GA) ends at its schedule even with a larger budget."""
    assert _progress.fit_budget("stribeck", "vsbas", {"delta": 1.0}, 200_000) == 3001
    assert _progress.fit_budget("stribeck", "vsbas", None, 1000) == 1000
    assert _progress.fit_budget("stribeck", "rwsavsbas", None, None) == 301_001
    assert _progress.fit_budget("stribeck", "de", None, 50_000) == 50_000  # runs to the budget
    assert _progress.fit_budget("stribeck", "lm", None, None) is None  # stops when converged
    assert _progress.fit_budget("rbf", "bas", None, None) is None


def test_fleet_piped_shows_progress(no_grace, tmp_path):
    from fricid.io import write_rawlog
    from fricid.sim import preset, simulate

    sc = preset("paper2", "quick")
    write_rawlog(simulate(sc, seed=0), tmp_path / "j0.parquet")
    manifest = tmp_path / "m.csv"
    manifest.write_text(
        "robot,joint,log,model,fix,gravity\nr0,j0,j0.parquet,stribeck,delta=1,none\n"
    )
    res = run("fleet", manifest, "--out", tmp_path / "out", "--workers", "1")
    assert res.exit_code == 0, res.output
    lines = progress_lines(res.stderr)
    assert lines and lines[-1].endswith("identifying joints: done (1/1 joints)"), res.stderr


# ------------------------------------------------------------------ numbers that read right


def test_extraction_summary_counts_read_right():
    from fricid.extract import extract
    from fricid.sim import preset, simulate

    sc = preset("paper1", "quick")
    r = extract(simulate(sc, seed=0), **sc.extract_options())
    first, second = r.summary().splitlines()[:2]
    n = len(r.samples)
    assert first.startswith(f"{n} samples (both directions combined; {n} + {n} per-direction")
    assert "per direction)" not in first
    reps = sc.design.repetitions
    assert f", {reps} passes per sample" in second and "-" not in second.split("),")[-1]
    from fricid.extract.result import _count, _passes

    assert _count(1, "temperature") == "1 temperature" and _count(2, "temperature") == (
        "2 temperatures"
    )
    assert _passes(1, 1) == "1 pass" and _passes(2, 4) == "2-4 passes"
    assert _count(1234567, "row") == "1,234,567 rows"


def test_cli_counts_are_plural_only_when_more_than_one():
    from fricid.cli._app import plural

    assert plural(1, "joint") == "1 joint" and plural(0, "joint") == "0 joints"
    assert plural(2, "pass", "passes") == "2 passes"


def test_evaluate_prints_rmspe_in_percent_and_sse_in_n2m2():
    assert metric_row("rmspe", 0.037) == ("RMSPE [%]", "3.7")
    assert metric_row("sse", 2.0)[0] == "SSE [N^2 m^2]"
    assert metric_row("rmse_pos", 0.5) == ("RMSE [N m], v > 0", "0.5")
    res = run("evaluate", "--help")
    assert "SSE [N^2 m^2]" in " ".join(res.stdout.split()) and "N m^2]" not in res.stdout


def test_evaluate_table_and_json_agree(tmp_path, samples_csv):
    model = tmp_path / "m.json"
    assert run("fit", samples_csv, "--model", "coulomb_viscous", "--out", model).exit_code == 0
    res = run("evaluate", model, samples_csv)
    assert res.exit_code == 0, res.output
    row = next(ln for ln in res.stdout.splitlines() if "RMSPE [%]" in ln)
    shown = float(row.split("│")[2])
    js = json.loads(run("evaluate", model, samples_csv, "--json").stdout)
    assert shown == pytest.approx(100 * js["rmspe"], rel=1e-5)  # JSON keeps the fraction


def test_tables_keep_whole_names_in_a_pipe(monkeypatch):
    """rich cuts a cell to 'coulomb_visc…' at 80 columns; not a terminal, fricid widens."""
    from rich.table import Table

    from fricid.cli._app import console

    monkeypatch.delenv("COLUMNS", raising=False)
    table = Table()
    for col in ("model", "fitness", "RMSE [mN m]", "RMSPE [%]", "max |err| [mN m]", "extra"):
        table.add_column(col)
    table.add_row("coulomb_viscous_asym", *["0.123456 [0.876543]"] * 5)
    with console.capture() as cap:
        console.print(table)
    assert console.width >= PIPE_WIDTH
    assert "coulomb_viscous_asym" in cap.get() and "…" not in cap.get()
    monkeypatch.setenv("COLUMNS", "80")  # an explicit width is obeyed
    assert console.width == 80


def test_methods_lists_every_stateful_model():
    from fricid.models import STATEFUL

    res = run("methods")
    assert res.exit_code == 0
    for name in STATEFUL:
        assert re.search(rf"^\s+{re.escape(name)}\s", res.stdout, re.M), name
    assert "rbf" in STATEFUL


def test_warning_labels_split_the_class_name_into_words(capsys):
    """The CLI's one-line warnings name their category in words (RateBiasWarning: 'rate bias')."""
    from fricid.cli import _app
    from fricid.errors import DataQualityWarning, FricidWarning
    from fricid.identify.dynamic.trajectory import RateBiasWarning

    for category, label in (
        (RateBiasWarning, "rate bias"),
        (DataQualityWarning, "data quality"),
        (FricidWarning, "warning"),
    ):
        _app._show_warning("text", category, "f.py", 1)
        assert f"warning ({label}): text" in capsys.readouterr().err


@pytest.mark.slow  # 4 s measured under load (two trajectory fits)
def test_fit_trajectory_names_each_stage_and_its_place(no_grace, tmp_path):
    """``fit --trajectory``: one line per stage with its place, no time left (stages of
    unequal cost); nothing with --quiet."""
    from fricid.io import write_rawlog
    from fricid.models import Stribeck
    from fricid.sim import Joint, ModelLaw
    from fricid.sim import trajectory as tr

    joint = Joint(law=lambda v, load, temp: np.zeros_like(v), p_x=0.3, p_y=0.1, inertia=0.01)
    law = ModelLaw(Stribeck(), np.array([0.5, 0.8, 0.1, 0.2, 1.0]))
    log = tr.simulate_trajectory(tr.multisine(duration=4.0, seed=2), law, joint, seed=2)
    path = write_rawlog(log, tmp_path / "traj.parquet")
    args = ("fit", path, "--trajectory", "--model", "stribeck", "--out", tmp_path / "m.json")
    res = run(*args)
    assert res.exit_code == 0, res.output
    lines = progress_lines(res.stderr)
    assert any("[1/4] checking the log" in ln for ln in lines), lines
    assert any("[2/4] regression: static friction, inertia, gravity" in ln for ln in lines)
    assert any("[3/4] derivative window: the encoder's noise" in ln for ln in lines), lines
    assert any("[4/4] intervals, passivity" in ln for ln in lines), lines
    assert not any(" left" in ln for ln in lines), lines
    res = run(*args[:-2], "-q", "--out", tmp_path / "q.json")
    assert res.exit_code == 0 and not progress_lines(res.stderr)


@pytest.mark.slow  # 3 s measured under load (a fit and a report with its figures)
def test_report_names_each_part_and_takes_quiet(no_grace, tmp_path, samples_csv):
    model = tmp_path / "m.json"
    assert run("fit", samples_csv, "--out", model, "-q").exit_code == 0
    res = run("report", model, samples_csv, "--out", tmp_path / "rep", "--no-validate")
    assert res.exit_code == 0, res.output
    lines = progress_lines(res.stderr)
    for part in ("the trust record", "figures: friction against velocity", "writing"):
        assert any(f"report: {part}" in ln for ln in lines), (part, lines)
    assert not any(" left" in ln for ln in lines), lines  # parts of unequal cost: not timed
    res = run("report", model, samples_csv, "--out", tmp_path / "rep2", "-q")
    assert res.exit_code == 0 and not progress_lines(res.stderr), res.stderr


def test_names_from_files_are_not_turned_into_emoji():
    """rich reads ``:m:`` as an emoji code; a base parameter named from a joint, ``joint2:m``,
    before a colon printed as ``joint2Ⓜ``. fricid's consoles print names as they are."""
    from fricid.cli._app import console, err_console

    for con in (console, err_console):
        with con.capture() as cap:
            con.print("joint1:mz +0.1 joint2:m: the URDF's values", markup=False)
        assert "joint2:m: the" in cap.get()
