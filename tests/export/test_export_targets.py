"""URDF, MJCF and YAML exports (the Coulomb-viscous projection), and the `fricid export` and
`fricid predict` commands."""

from __future__ import annotations

import json
import re
import warnings
import xml.etree.ElementTree as ET

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
import yaml
from typer.testing import CliRunner

from fricid.cli import app
from fricid.export import (
    ExportError,
    mjcf_text,
    operating_grid,
    project,
    ros2_yaml_text,
    urdf_text,
)
from fricid.fitted import SCHEMA_VERSION, FittedModel, OptimizerRecord
from fricid.identify import fit
from fricid.samples import FrictionSamples

runner = CliRunner()


def run(*args):
    return runner.invoke(app, [str(a) for a in args])


RANGE = {"velocity": [0.005, 4.0], "load": [0.0, 0.0], "temperature": [25.0, 25.0]}
PAPER2 = {"tau_c": 0.084, "tau_s": 0.641, "w_s": 0.066, "tau_v": 0.0026, "delta": 1.0}


def cv_asym() -> FittedModel:
    return FittedModel.from_values(
        "coulomb_viscous_asym",
        {"f_c_pos": 0.3, "beta_pos": 0.1, "f_c_neg": 0.2, "beta_neg": 0.15},
        operating_range={"velocity": [-2.0, 2.0], "load": [0, 0], "temperature": [25, 25]},
    )


def stribeck() -> FittedModel:
    return FittedModel.from_values(
        "stribeck",
        dict(PAPER2),
        operating_range=RANGE,
        optimizer=OptimizerRecord(method="lm", seed=0),
    )


@pytest.fixture
def model_file(tmp_path):
    return stribeck().save(tmp_path / "stribeck.json")


# -- projection -----------------------------------------------------------------------------


def test_projection_of_coulomb_viscous_is_exact():
    f = FittedModel.from_values("coulomb_viscous", {"f_c": 0.3, "beta": 0.1}, operating_range=RANGE)
    p = project(f)
    assert p.coulomb["both"] == pytest.approx(0.3, rel=1e-9)
    assert p.viscous["both"] == pytest.approx(0.1, rel=1e-9)
    assert p.rms_error < 1e-12 and p.lost == []


def test_per_direction_projection_recovers_each_side():
    p = project(cv_asym(), per_direction=True)
    assert p.coulomb == pytest.approx({"positive": 0.3, "negative": 0.2}, rel=1e-9)
    assert p.viscous == pytest.approx({"positive": 0.1, "negative": 0.15}, rel=1e-9)
    assert p.rms_error < 1e-12
    both = project(cv_asym())
    assert both.rms_error > 0.01
    assert any("direction asymmetry" in x for x in both.lost)


def test_projection_is_least_squares_over_the_grid():
    f = stribeck()
    p = project(f)
    X, info = operating_grid(f)
    assert info["mirrored"] and info["speed"] == (0.005, 4.0)
    F = f.predict(X)
    s, v = np.sign(X[:, 0]), X[:, 0]
    best = p.coulomb["both"] * s + p.viscous["both"] * v
    rms = np.sqrt(np.mean((best - F) ** 2))
    assert rms == pytest.approx(p.rms_error, rel=1e-9)
    for dc, db in ((1e-3, 0), (-1e-3, 0), (0, 1e-4)):  # no nearby feasible pair does better
        other = (p.coulomb["both"] + dc) * s + max(p.viscous["both"] + db, 0) * v
        assert np.sqrt(np.mean((other - F) ** 2)) >= rms
    assert any("Stribeck break-away" in x for x in p.lost)


def test_a_per_direction_models_break_away_is_given_for_each_direction():
    """The slowest point of each direction: a new user's lugre_asym export gave only the
    backward break-away (0.8575 N m; forwards 1.217)."""
    both = {f"{k}{side}": v for side in ("_pos", "_neg") for k, v in PAPER2.items()}
    both["tau_s_neg"] = 0.5 * PAPER2["tau_s"]
    f = FittedModel.from_values("stribeck_asym", both, operating_range=RANGE)
    (line,) = (x for x in project(f).lost if "Stribeck break-away" in x)
    X, _ = operating_grid(f)
    F = f.predict(X)
    for word, side in (("forwards", X[:, 0] > 0), ("backwards", X[:, 0] < 0)):
        slow = side & (np.abs(X[:, 0]) == np.abs(X[side, 0]).min())
        assert f"{np.abs(F[slow]).max():.4g} N m {word}" in line


def test_load_and_temperature_dependence_reported_lost():
    f = FittedModel.from_values(
        "msk",
        {
            "f_c": 0.04,
            "f_s": 0.12,
            "f_ck": 0.6,
            "f_sk": 0.3,
            "v_s": 0.035,
            "xi": 1.5,
            "beta": 0.2,
        },
        operating_range={"velocity": [0.01, 1.0], "load": [0.15, 0.21], "temperature": [5, 45]},
    )
    lost = " ".join(project(f).lost)
    assert "load dependence (load 0.15 to 0.21 N m)" in lost
    assert "temperature" not in lost  # msk does not use temperature


def test_missing_operating_range_is_explained():
    f = FittedModel.from_values("coulomb_viscous", {"f_c": 0.3, "beta": 0.1})
    with pytest.raises(ExportError, match="no operating range for velocity"):
        project(f)
    assert project(f, velocity_range=(0.1, 1), load_range=0, temperature_range=25).rms_error < 1e-9


# -- the texts ------------------------------------------------------------------------------


def comment_of(text: str) -> str:
    return re.search(r"<!--(.*?)-->", text, re.S).group(1)


def test_urdf_and_mjcf_parse_and_state_the_error():
    f = stribeck()
    p = project(f)
    urdf = urdf_text(f, joint="elbow")
    dyn = ET.fromstring(urdf.split("-->")[1])
    assert float(dyn.get("friction")) == p.coulomb["both"]
    assert float(dyn.get("damping")) == p.viscous["both"]
    assert "projection error: RMS" in comment_of(urdf) and "Stribeck" in comment_of(urdf)
    mjcf = mjcf_text(f, joint="elbow")
    joint = ET.fromstring(mjcf.split("-->")[1])
    assert joint.get("name") == "elbow"
    assert float(joint.get("frictionloss")) == p.coulomb["both"]
    assert "projection error" in comment_of(mjcf)


def test_yaml_has_per_direction_parameters():
    text = ros2_yaml_text(cv_asym(), joint="elbow")
    doc = yaml.safe_load(text)
    params = doc["friction_compensation"]["ros__parameters"]
    assert params["joints"] == ["elbow"]
    assert params["elbow"]["coulomb_positive"] == pytest.approx(0.3)
    assert params["elbow"]["coulomb_negative"] == pytest.approx(0.2)
    assert params["elbow"]["viscous_negative"] == pytest.approx(0.15)
    assert "# projection error: RMS" in text


def test_target_that_cannot_represent_the_model_says_what_is_lost():
    with pytest.raises(ExportError) as info:
        urdf_text(cv_asym(), max_loss=0.05)
    msg = str(info.value)
    assert "URDF <dynamics> cannot represent model 'coulomb_viscous_asym'" in msg
    assert "Lost: the direction asymmetry" in msg and "--max-loss" in msg
    with pytest.raises(ExportError, match="joint name"):
        mjcf_text(stribeck(), joint='a"b')


# -- the commands ---------------------------------------------------------------------------


def test_export_c_command(tmp_path, model_file):
    res = run(
        "export",
        model_file,
        "--to",
        "c",
        "--out",
        tmp_path / "c",
        "--smooth",
        "tanh",
        "--zone",
        "0.005",
    )
    assert res.exit_code == 0, res.output
    assert "tanh(velocity / 0.005)" in (tmp_path / "c" / "fricid_friction.c").read_text()


def test_export_description_commands(tmp_path, model_file):
    res = run("export", model_file, "--to", "urdf", "--joint", "elbow")
    assert res.exit_code == 0, res.output
    assert "<dynamics damping=" in res.stdout
    out = tmp_path / "robot" / "elbow.yaml"
    res = run("export", model_file, "--to", "yaml", "--out", out)
    assert res.exit_code == 0, res.output
    assert yaml.safe_load(out.read_text())["friction_compensation"]["ros__parameters"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--to", "sdf"], "unknown export target 'sdf'; choose one of: c, urdf, mjcf, yaml"),
        (["--to", "urdf", "--max-loss", "0.1"], "Lost: the velocity shape of 'stribeck'"),
        (["--to", "c", "--smooth", "cubic", "--zone", "1"], "unknown smoothing 'cubic'"),
        (["--to", "c", "--smooth", "linear"], "needs a zone half-width > 0"),
    ],
)
def test_export_errors_write_nothing(tmp_path, model_file, args, message):
    out = tmp_path / "out"
    res = run("export", model_file, *args, "--out", out)
    assert res.exit_code == 2, res.output
    assert message in " ".join(res.output.split())
    assert not out.exists()


def test_export_refuses_a_newer_model_file(tmp_path):
    d = stribeck().to_dict()
    d["schema_version"] = SCHEMA_VERSION + 1
    path = tmp_path / "new.json"
    path.write_text(json.dumps(d))
    res = run("export", path, "--to", "c", "--out", tmp_path / "c")
    assert res.exit_code == 2
    assert "newer than this fricid" in res.output and "Traceback" not in res.output
    assert not (tmp_path / "c").exists()


def test_predict_points_with_units(model_file):
    res = run(
        "predict",
        model_file,
        "--velocity",
        "1",
        "--velocity",
        "-2",
        "--velocity-unit",
        "deg/s",
        "--friction-unit",
        "mNm",
    )
    assert res.exit_code == 0, res.output
    lines = res.stdout.strip().splitlines()
    # stribeck depends on neither load nor temperature: no made-up 0 N m or 25 degC column
    assert lines[0] == "velocity [deg/s],friction [mNm]"
    got = np.array([[float(x) for x in line.split(",")] for line in lines[1:]])
    want = stribeck().predict_point(np.deg2rad([1.0, -2.0])) * 1e3
    np.testing.assert_allclose(got[:, 1], want, rtol=1e-15)
    np.testing.assert_array_equal(got[:, 0], [1.0, -2.0])


def test_predict_file_of_points(tmp_path, model_file):
    v = np.linspace(-3, 3, 7)
    csv = tmp_path / "points.csv"
    csv.write_text(
        "# from a test\ntime [s],velocity [rad/s]\n"
        + "".join(f"{i},{float(x)!r}\n" for i, x in enumerate(v))
    )
    out = tmp_path / "friction.csv"
    res = run("predict", model_file, "--input", csv, "--out", out)
    assert res.exit_code == 0, res.output
    table = np.loadtxt(out, delimiter=",", skiprows=1)
    np.testing.assert_allclose(table[:, -1], stribeck().predict_point(v), rtol=1e-15)
    pq_path = tmp_path / "points.parquet"
    pq.write_table(pa.table({"velocity": v}), pq_path)
    res = run("predict", model_file, "--input", pq_path, "--velocity-unit", "rpm")
    assert res.exit_code == 0, res.output
    got = np.loadtxt(res.stdout.splitlines()[1:], delimiter=",")
    np.testing.assert_allclose(got[:, -1], stribeck().predict_point(v * np.pi / 30), rtol=1e-15)


def test_predict_refuses_mixed_units_and_missing_inputs(tmp_path, model_file):
    csv = tmp_path / "points.csv"
    csv.write_text("velocity [deg/s]\n1\n2\n")
    res = run("predict", model_file, "--input", csv, "--velocity-unit", "rad/s")
    assert res.exit_code == 2
    assert "mixed units" in res.output
    vlt = FittedModel.from_values(
        "vlt",
        {
            "f_c": 0.05,
            "f_ctl": 0.6,
            "f_stl": 0.3,
            "f_v0": 0.2,
            "f_vT": -0.002,
            "v_tl0": 0.035,
            "v_v0": 0.4,
            "v_vT": 0.01,
        },
    ).save(tmp_path / "vlt.json")
    res = run("predict", vlt, "--velocity", "0.1", "--load", "0.2")
    assert res.exit_code == 2
    assert "depends on temperature" in res.output
    res = run("predict", model_file, "--velocity", "0.1", "--velocity-unit", "furlong/s")
    assert res.exit_code == 2 and "unknown velocity unit" in res.output


def test_rbf_network_projects_and_predicts(tmp_path):
    from test_export import rbf_fitted

    fitted = rbf_fitted(("velocity", "load"), 0.02)
    p = project(fitted)
    assert "the RBF network's shape" in " ".join(p.lost)
    assert "load dependence" in " ".join(p.lost) and "temperature" not in " ".join(p.lost)
    path = fitted.save(tmp_path / "rbf.json")
    res = run("predict", path, "--velocity", "0.1", "--load", "0.2")
    assert res.exit_code == 0, res.output
    value = float(res.stdout.splitlines()[1].split(",")[-1])
    assert value == pytest.approx(fitted.predict_point(0.1, 0.2), rel=1e-15)
    res = run("predict", path, "--velocity", "0.1")
    assert res.exit_code == 2 and "depends on load" in res.output
    res = run(
        "export", path, "--to", "c", "--smooth", "tanh", "--zone", "0.01", "--out", tmp_path / "c"
    )
    # the network is sign(v) g(|v|) (issue 11, defect 1), so tanh smoothing applies to it
    assert res.exit_code == 0, res.output
    assert (tmp_path / "c" / "fricid_friction.c").exists()


def test_learned_models_ask_only_for_the_inputs_they_use(tmp_path):
    """A GP or hybrid whose processes or networks dropped load and temperature (constant in
    the data) predicts without --load and --temperature, at the values they were measured
    at; before, it demanded both and then ignored them."""
    rng = np.random.default_rng(0)
    s = np.geomspace(0.05, 3.0, 12)
    v = np.r_[s, -s]
    samples = FrictionSamples(
        velocity=v,
        load=np.full(v.size, 2.0),
        temperature=np.full(v.size, 40.0),
        friction=np.sign(v) * (0.5 + 0.2 * np.abs(v)) + 0.01 * rng.standard_normal(v.size),
    )
    for name in ("gp", "hybrid"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            path = fit(samples, name).save(tmp_path / f"{name}.json")
        res = run("predict", path, "--velocity", "0.5", "--interval", "0.95")
        assert res.exit_code == 0, res.output
        row = res.stdout.splitlines()[1].split(",")
        assert (float(row[1]), float(row[2])) == (2.0, 40.0)  # as measured, no range warning
        assert "outside the identified range" not in res.stderr


def test_a_one_direction_model_says_its_other_side_is_not_measured():
    """Samples of one direction (direction +1) give a model whose other side the projection
    mirrors: the comment said "mirrored: direction-combined model", as if both were measured."""
    combined = stribeck()
    combined.provenance = {"directions": [0]}
    assert "(mirrored: direction-combined model)" in project(combined).summary()[0]
    one = stribeck()
    one.provenance = {"directions": [1]}
    head = project(one).summary()[0]
    assert "direction-combined" not in head
    assert "identified for positive velocity only: the negative side is its mirror image" in head
    assert "not measured" in head
    one.provenance = {"directions": [-1]}
    assert "identified for negative velocity only" in project(one).summary()[0]


def test_a_both_direction_model_is_projected_over_its_measured_speeds(tmp_path):
    """A model of both directions (a range spanning zero) was projected from 1/200 of its
    largest speed: the lead screw's from 0.104 rad/s, below its slowest measured 0.217, where
    predict calls it an extrapolation; each side now starts at its slowest measured speed."""
    rng = np.random.default_rng(0)
    speeds = np.geomspace(0.2, 4.0, 8)
    v = np.r_[speeds, -1.1 * speeds]
    samples = FrictionSamples(
        velocity=v,
        load=np.zeros(v.size),
        temperature=np.full(v.size, 25.0),
        friction=np.sign(v) * (0.3 + 0.05 * np.abs(v)) + 0.001 * rng.standard_normal(v.size),
        direction=np.sign(v),
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit(samples, "coulomb_viscous_asym")
    X, info = operating_grid(fitted)
    assert np.abs(X[X[:, 0] > 0, 0]).min() == pytest.approx(0.2)
    assert np.abs(X[X[:, 0] < 0, 0]).min() == pytest.approx(0.22)
    assert info["speed"][0] == pytest.approx(0.2)
    assert "|velocity| 0.2 to 4.4 rad/s" in project(fitted, True).summary()[0]
