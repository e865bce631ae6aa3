"""The command line: the chain end to end, and bad input as one line with exit status 2."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from fricid.cli import app

runner = CliRunner()


def run(*args: str):
    return runner.invoke(app, [str(a) for a in args])


@pytest.fixture(scope="module")
def demo_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo")
    res = run("demo", "--size", "quick", "--out", out)
    assert res.exit_code == 0, res.output
    return out


def test_demo_writes_everything_and_prints_table1(demo_dir):
    for name in (
        "samples.csv",
        "samples_by_direction.csv",
        "table1.csv",
        "summary.md",
        "coulomb_viscous.json",
        "stribeck.json",
        "msk.json",
        "vlt.json",
    ):
        assert (demo_dir / name).stat().st_size > 0, name
    assert "0.9783" in (demo_dir / "summary.md").read_text()  # the paper's number beside ours


def test_fit_and_evaluate(demo_dir, tmp_path):
    out = tmp_path / "m.json"
    res = run(
        "fit", demo_dir / "samples.csv", "--model", "stribeck", "--fix", "delta=1", "--out", out
    )
    assert res.exit_code == 0, res.output
    assert "tau_c" in res.output and "95 % CI" in res.output
    assert json.loads(out.read_text())["params"]["delta"] == 1.0
    res = run("evaluate", out, demo_dir / "samples.csv", "--json")
    assert res.exit_code == 0, res.output
    assert 0.0 < json.loads(res.stdout)["fitness"] <= 1.0


def test_simulate_then_extract(tmp_path):
    log = tmp_path / "log.parquet"
    res = run("simulate", "--preset", "paper2", "--size", "quick", "--out", log)
    assert res.exit_code == 0, res.output
    samples = tmp_path / "s.csv"
    res = run("extract", log, "--out", samples, "--by-direction", tmp_path / "d.csv")
    assert res.exit_code == 0, res.output
    assert samples.exists() and (tmp_path / "d.csv").exists()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["fit", "{samples}", "--model", "nope"], "unknown model 'nope'"),
        (["fit", "{samples}", "--method", "nope"], "unknown method 'nope'"),
        (["fit", "{samples}", "--fix", "xi=1"], "cannot fix unknown parameter"),
        (
            ["fit", "{samples}", "--model", "stribeck_asym", "--direction", "combined"],
            "combine both directions",
        ),
        (["fit", "{bad}"], "bad.csv"),
        (["extract", "{samples}", "--positions", "1:0:1"], "--positions takes"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(demo_dir, tmp_path, args, message):
    bad = tmp_path / "bad.csv"
    bad.write_text("velocity [rad/s],load [N m],temperature [degC],friction [N m]\n0.1,0,25,x\n")
    args = [a.format(samples=demo_dir / "samples.csv", bad=bad) for a in args]
    out = tmp_path / "never.json"
    res = run(*args, "--out", out)
    assert res.exit_code == 2, res.output
    assert message in res.output
    assert "Traceback" not in res.output
    assert not out.exists()


def test_help_mentions_units():
    for cmd in ("fit", "extract", "simulate", "demo", "evaluate"):
        res = run(cmd, "--help")
        assert res.exit_code == 0
    assert "rad/s" in run("extract", "--help").output
