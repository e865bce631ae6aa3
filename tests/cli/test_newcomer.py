"""What a new user meets first: ``fricid methods``, the options' help and errors, the fit
report, the numbers ``predict`` prints."""

from __future__ import annotations

import contextlib
import re

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app

runner = CliRunner()


def run(*args):
    return runner.invoke(app, [str(a) for a in args])


@pytest.fixture(scope="module")
def samples_csv(tmp_path_factory):
    v = np.geomspace(0.01, 1.0, 8)
    v = np.concatenate([v, -v])
    f = np.sign(v) * (0.1 + 0.05 * np.exp(-((v / 0.05) ** 2))) + 0.02 * v
    f = f + 1e-4 * np.random.default_rng(0).standard_normal(v.size)
    path = tmp_path_factory.mktemp("newcomer") / "s.csv"
    rows = "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(v, f, strict=True))
    path.write_text("velocity [rad/s],friction [N m]\n" + rows)
    return path


def test_methods_lists_every_model_and_optimiser_from_the_registries():
    from fricid.errors import ConfigError
    from fricid.models import DYNAMIC, MODELS, STATEFUL, get_model
    from fricid.optim import METHODS

    res = run("methods")
    assert res.exit_code == 0, res.output
    listed = set(re.findall(r"^  (\S+)\s", res.stdout, re.M))
    temp = set()
    for name in MODELS:
        with contextlib.suppress(ConfigError):
            temp.add(get_model(f"{name}_temp").name)
    assert {"stribeck_temp", "msk_temp", "coulomb_viscous_temp"} <= temp
    want = {*MODELS, *temp, *DYNAMIC, *STATEFUL, "auto", *METHODS, "varpro"}
    assert {"lugre", "dahl"} <= want
    assert want == listed, (want - listed, listed - want)
    for line in res.stdout.splitlines():  # one line each, with a description
        if line.startswith("  "):
            assert len(line.split(None, 1)) == 2, line


def test_method_help_names_each_model_s_default():
    res = run("fit", "--help")
    assert res.exit_code == 0
    text = " ".join(res.stdout.split())
    assert "lsq for rbf and hybrid" in text
    assert "[default: lm]" not in text


@pytest.mark.slow  # 11 s measured under load (the network's structure search, the trust check)
def test_rbf_trains_with_lsq_without_method(samples_csv, tmp_path):
    out = tmp_path / "r.json"
    res = run("fit", samples_csv, "--model", "rbf", "--centers", "4", "-q", "--out", out)
    assert res.exit_code == 0, res.output
    import json

    assert json.loads(out.read_text())["state"]["trainer"] == "lsq"


def test_too_many_centres_names_the_command_line_option(samples_csv, tmp_path):
    res = run("fit", samples_csv, "--model", "rbf", "--centers", "1000", "--out", tmp_path / "x")
    assert res.exit_code == 2
    assert "--centers" in res.output and "Traceback" not in res.output


def test_the_fit_report_states_the_rmse(samples_csv):
    from fricid.identify import fit
    from fricid.io import read_samples

    fitted = fit(read_samples(samples_csv), "coulomb_viscous")
    line = next(ln for ln in fitted.report().splitlines() if "RMSE" in ln)
    assert line.split("=")[0].strip() == "RMSE [N m]"
    assert float(line.split("=")[1]) == pytest.approx(fitted.metrics["rmse"], rel=1e-7)


def test_predict_prints_numbers_with_the_digits_they_deserve(samples_csv, tmp_path):
    from fricid.identify import fit
    from fricid.io import read_samples

    model = fit(read_samples(samples_csv), "coulomb_viscous").save(tmp_path / "m.json")
    res = run("predict", model, "-v", "0.2", "-v", "0.1", "--load", "0.3", "--temperature", "25")
    assert res.exit_code == 0, res.output
    rows = res.stdout.splitlines()
    assert rows[1].startswith("0.2,0.3,25,") and "0.20000000000000001" not in res.stdout
    from fricid.fitted import FittedModel

    fitted = FittedModel.load(model)
    exact = fitted.predict(np.array([[0.2, 0.3, 25.0]]))[0]
    assert float(rows[1].split(",")[3]) == exact  # exact: reads back to the same float
    res = run("predict", model, "-v", "0.2", "--digits", "3")
    assert res.stdout.splitlines()[1].split(",")[-1] == f"{exact:.3g}"


def test_predict_says_a_load_or_temperature_the_model_ignores(samples_csv, tmp_path):
    """A new user's trial: 'predict m.json -v 0.5 --temperature 80' on a velocity-only model
    echoed 80 degC beside the friction of the 25 degC data, silently."""
    from fricid.identify import fit
    from fricid.io import read_samples

    model = fit(read_samples(samples_csv), "coulomb_viscous").save(tmp_path / "m.json")
    res = run("predict", model, "-v", "0.5", "--temperature", "80", "--load", "0.3")
    assert res.exit_code == 0, res.output
    assert "does not depend on load" in res.stderr and "does not depend on temperature" in (
        res.stderr
    ), res.stderr
    res = run("predict", model, "-v", "0.5")  # nothing given: nothing said
    assert "does not depend" not in res.stderr, res.stderr


def test_predict_writes_no_made_up_temperature_for_a_model_without_one(samples_csv, tmp_path):
    """A velocity-only model's predictions carried a temperature column of 25 degC that no one
    gave and the friction does not depend on; written only when given or used."""
    from fricid.fitted import FittedModel
    from fricid.identify import fit
    from fricid.io import read_samples

    samples = read_samples(samples_csv)
    model = fit(samples, "stribeck").save(tmp_path / "m.json")
    res = run("predict", model, "-v", "0.5", "-v", "-0.5")
    assert res.exit_code == 0, res.output
    rows = res.stdout.splitlines()
    assert rows[0] == "velocity [rad/s],friction [N m]"
    friction = [float(row.split(",")[-1]) for row in rows[1:]]
    exact = FittedModel.load(model).predict(np.array([[0.5, 0, 25], [-0.5, 0, 25]]))
    np.testing.assert_array_equal(friction, exact)
    res = run("predict", model, "-v", "0.5", "--temperature", "80")  # given: echoed, as said
    assert res.stdout.splitlines()[0].split(",")[1] == "temperature [degC]"
    assert res.stdout.splitlines()[1].split(",")[1] == "80"
    points = tmp_path / "points.csv"
    points.write_text("velocity [rad/s],temperature [degC]\n0.5,40\n")
    res = run("predict", model, "--input", points)
    assert res.stdout.splitlines()[1].split(",")[1] == "40"
    hot = type(samples)(  # two temperatures: a model that uses temperature
        velocity=np.tile(samples.velocity, 2),
        load=0.0,
        temperature=np.repeat([20.0, 60.0], len(samples)),
        friction=np.concatenate([samples.friction, 0.9 * samples.friction]),
    )
    temp_model = fit(hot, "stribeck_temp").save(tmp_path / "t.json")
    res = run("predict", temp_model, "-v", "0.5", "--temperature", "30")
    assert res.exit_code == 0, res.output
    assert res.stdout.splitlines()[0] == "velocity [rad/s],temperature [degC],friction [N m]"


def test_predict_writes_no_made_up_load_for_a_model_without_one(samples_csv, tmp_path):
    """The same for load: a velocity-only model's output carried load 0 N m no one gave."""
    from fricid.identify import fit
    from fricid.io import read_samples

    model = fit(read_samples(samples_csv), "stribeck").save(tmp_path / "m.json")
    res = run("predict", model, "-v", "0.5", "-v", "-0.5")
    assert res.exit_code == 0, res.output
    assert res.stdout.splitlines()[0] == "velocity [rad/s],friction [N m]"
    res = run("predict", model, "-v", "0.5", "--load", "2")  # given: echoed
    assert res.stdout.splitlines()[0] == "velocity [rad/s],load [N m],friction [N m]"
