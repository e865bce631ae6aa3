"""C export: every model family compiled with the system C compiler and compared with Python."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest

from _c_harness import (
    SMOOTHINGS,
    compile_and_run,
    compile_c,
    needs_cc,
    points,
    relative_error,
    sum_scale,
    zone_scale,
)
from fricid.errors import ConfigError
from fricid.export import ExportError, Smoothing, c_code, export_c, smooth_predict
from fricid.fitted import FittedModel, OptimizerRecord
from fricid.models import MODELS, get_model

#: Parameters of each family, per direction (the negative side differs on purpose).
PARAMS = {
    "coulomb_viscous": ({"f_c": 0.3, "beta": 0.11}, {"f_c": 0.21, "beta": 0.17}),
    "stribeck": (
        {"tau_c": 0.084, "tau_s": 0.641, "w_s": 0.066, "tau_v": 0.0026, "delta": 1.0},
        {"tau_c": 0.07, "tau_s": 0.52, "w_s": 0.05, "tau_v": 0.004, "delta": 1.7},
    ),
    "msk": (
        {"f_c": 0.04, "f_s": 0.12, "f_ck": 0.6, "f_sk": 0.3, "v_s": 0.035, "xi": 1.5, "beta": 0.2},
        {"f_c": 0.05, "f_s": 0.1, "f_ck": 0.5, "f_sk": 0.35, "v_s": 0.03, "xi": 1.2, "beta": 0.25},
    ),
    "vlt": (
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
        {
            "f_c": 0.04,
            "f_ctl": 0.55,
            "f_stl": 0.35,
            "f_v0": 0.25,
            "f_vT": -0.003,
            "v_tl0": 0.03,
            "v_v0": 0.5,
            "v_vT": 0.008,
        },
    ),
}

RANGE = {"velocity": [-1.0, 1.0], "load": [-0.5, 0.5], "temperature": [5.0, 45.0]}


def make_fitted(family: str, asym: bool) -> FittedModel:
    pos, neg = PARAMS[family]
    if asym:
        params = {f"{k}_pos": v for k, v in pos.items()} | {f"{k}_neg": v for k, v in neg.items()}
        name = f"{family}_asym"
    else:
        params, name = dict(pos), family
    return FittedModel.from_values(
        name, params, operating_range=RANGE, optimizer=OptimizerRecord(method="test", seed=0)
    )


@pytest.mark.slow  # 6 s measured under load (default run kept short)
@needs_cc
@pytest.mark.parametrize("asym", [False, True], ids=["sym", "asym"])
@pytest.mark.parametrize("family", sorted(PARAMS))
def test_c_matches_python_to_1e12(tmp_path, family, asym):
    fitted = make_fitted(family, asym)
    X = points()
    for k, smoothing in enumerate(SMOOTHINGS):
        out = tmp_path / str(k)
        paths = export_c(fitted, out, smoothing, source="test")
        assert [p.name for p in paths] == ["fricid_friction.h", "fricid_friction.c"]
        got = compile_and_run(out, X)
        want = smooth_predict(fitted, X, smoothing)
        scale = zone_scale(fitted, X, smoothing)
        assert relative_error(got, want, scale) <= 1e-12, (family, asym, smoothing)


def test_every_analytic_family_has_a_c_template():
    assert set(PARAMS) == set(MODELS)


def test_c_is_real_time_fit():
    code = c_code(make_fitted("msk", True), Smoothing("linear", 0.01))
    includes = [line for line in code.source.splitlines() if line.startswith("#include")]
    assert includes == ['#include "fricid_friction.h"', "#include <math.h>"]
    for word in ("malloc", "calloc", "realloc", "free(", "printf", "static double *"):
        assert word not in code.source
    assert "double fricid_friction(double velocity, double load, double temperature);" in (
        code.header
    )
    assert "linear: |v| < 0.01 rad/s" in code.header


def test_smoothing_definitions():
    fitted = make_fitted("stribeck", False)
    v = np.array([-1.0, -0.03, -0.01, -0.001, 0.0, 0.001, 0.01, 0.03, 1.0])
    X = np.column_stack([v, np.zeros_like(v), np.full_like(v, 25.0)])
    exact = fitted.predict(X)
    lin = smooth_predict(fitted, X, Smoothing("linear", 0.01))
    # exact outside the zone, a straight line inside through the zone edges
    np.testing.assert_array_equal(lin[[0, 1, 2, 6, 7, 8]], exact[[0, 1, 2, 6, 7, 8]])
    assert lin[4] == pytest.approx(0.0, abs=1e-15)
    assert lin[5] == pytest.approx(exact[6] * 0.1, rel=1e-12)
    th = smooth_predict(fitted, X, Smoothing("tanh", 0.001))
    assert th[4] == 0.0 and abs(th[5]) < abs(exact[5])
    np.testing.assert_allclose(th[[0, 8]], exact[[0, 8]], rtol=1e-12)  # far from the zone


def test_asymmetric_smoothing_is_continuous_at_zero():
    fitted = make_fitted("stribeck", True)
    v = np.array([-1e-9, 0.0, 1e-9])
    X = np.column_stack([v, np.zeros(3), np.full(3, 25.0)])
    for smoothing in SMOOTHINGS[1:]:
        f = smooth_predict(fitted, X, smoothing)
        assert np.ptp(f) < 1e-6, smoothing
    # the exact per-direction model jumps by both Coulomb levels
    assert np.ptp(fitted.predict(X)) > 0.1


def test_unrepresentable_c_exports_say_so_and_write_nothing(tmp_path):
    fitted = make_fitted("stribeck", False)
    with pytest.raises(ExportError, match="not a C identifier"):
        export_c(fitted, tmp_path / "a", prefix="1bad")
    with pytest.raises(ConfigError, match="needs a zone half-width"):
        export_c(fitted, tmp_path / "b", Smoothing("tanh", 0.0))
    unknown = make_fitted("stribeck", False)
    unknown.model = "gms"  # not registered ("lugre" is, since issue 16)
    with pytest.raises(Exception, match="unknown model 'gms'"):
        export_c(unknown, tmp_path / "c")
    unknown.model = "lugre"  # a registered dynamic model without a C template
    with pytest.raises(Exception, match="no template for the model family 'lugre'"):
        export_c(unknown, tmp_path / "d")
    assert not any(tmp_path.iterdir())


def rbf_fitted(inputs, velocity_scale=None, n_centers=15) -> FittedModel:
    """A small RBF network trained (least squares) on the paper1 law of the virtual joint."""
    from fricid.identify.learned.rbf import fit_rbf
    from fricid.samples import FrictionSamples
    from fricid.sim import LoadTemperatureLaw

    rng = np.random.default_rng(1)
    n = 400
    v = 10.0 ** rng.uniform(-3, 0, n) * rng.choice([-1.0, 1.0], n)
    load = rng.uniform(0.15, 0.21, n)
    temp = rng.uniform(5, 45, n)
    s = FrictionSamples(
        velocity=v, load=load, temperature=temp, friction=LoadTemperatureLaw()(v, load, temp)
    )
    return fit_rbf(s, inputs, n_centers=n_centers, velocity_scale=velocity_scale, random_state=0)


@needs_cc
@pytest.mark.parametrize(
    ("inputs", "velocity_scale"),
    [
        (("velocity", "load", "temperature"), 0.02),
        (("velocity",), None),
        (("temperature", "velocity"), None),
    ],
)
def test_rbf_c_matches_python(tmp_path, inputs, velocity_scale):
    fitted = rbf_fitted(inputs, velocity_scale)
    fitted = FittedModel.load(fitted.save(tmp_path / "rbf.json"))  # through the model file
    X = points()
    for k, smoothing in enumerate([Smoothing(), Smoothing("linear", 0.02)]):
        out = tmp_path / str(k)
        export_c(fitted, out, smoothing)
        got = compile_and_run(out, X)
        want = smooth_predict(fitted, X, smoothing)
        scale = zone_scale(fitted, X, smoothing)
        scale = np.maximum(0.0 if scale is None else scale, sum_scale(fitted, X))
        assert relative_error(got, want, scale) <= 1e-12, (inputs, smoothing)


def test_rbf_tanh_is_refused(tmp_path):
    rbf = FittedModel(model="rbf", state={"centers": [[0.0]]})
    with pytest.raises(ExportError, match="stored on signed velocity and has no sign term"):
        export_c(rbf, tmp_path, Smoothing("tanh", 0.01))
    assert not any(tmp_path.iterdir())


@needs_cc
def test_prefix_lets_two_joints_link_together(tmp_path):
    a = c_code(make_fitted("stribeck", False), prefix="elbow")
    b = c_code(make_fitted("vlt", True), prefix="wrist")
    for code in (a, b):
        (tmp_path / code.header_name).write_text(code.header)
        (tmp_path / code.source_name).write_text(code.source)
    (tmp_path / "main.c").write_text(
        '#include <stdio.h>\n#include "elbow_friction.h"\n#include "wrist_friction.h"\n'
        'int main(void) { printf("%.17g %.17g\\n", elbow_friction(0.5, 0.0, 25.0), '
        "wrist_friction(-0.5, 0.2, 30.0)); return 0; }\n"
    )
    exe = compile_c(tmp_path, ["main.c", "elbow_friction.c", "wrist_friction.c"], "two")
    got = [
        float(x)
        for x in subprocess.run(
            [str(exe)], capture_output=True, text=True, check=True
        ).stdout.split()
    ]
    want = [
        make_fitted("stribeck", False).predict_point(0.5, 0.0, 25.0),
        make_fitted("vlt", True).predict_point(-0.5, 0.2, 30.0),
    ]
    np.testing.assert_allclose(got, want, rtol=1e-12)


def test_get_model_names_cover_asym():
    # the per-direction variant of every family is exported through the same templates
    for family in PARAMS:
        assert get_model(f"{family}_asym").is_asymmetric


def test_linear_smoothing_keeps_the_sign_of_a_per_direction_model():
    """One chord from F(-zone) to F(+zone) crossed zero off the origin where the two
    directions' levels differ: friction of the wrong sign at slow speeds (found by a new
    user on the lead screw's stribeck_asym). Two lines through the origin never do."""
    fitted = make_fitted("stribeck", True)
    zone = 0.01
    v = np.r_[-np.geomspace(1e-6, zone, 30)[::-1], 0.0, np.geomspace(1e-6, zone, 30)]
    X = np.column_stack([v, np.zeros_like(v), np.full_like(v, 25.0)])
    edges = fitted.predict(np.array([[zone, 0.0, 25.0], [-zone, 0.0, 25.0]]))
    assert abs(edges[0]) != pytest.approx(abs(edges[1]), rel=1e-3)  # asymmetric levels
    lin = smooth_predict(fitted, X, Smoothing("linear", zone))
    assert np.all(np.sign(lin) == np.sign(v))


def test_a_dahl_model_exported_to_mjcf_says_what_it_leaves_out():
    """Its steady state is Coulomb-viscous, exactly: no velocity shape is lost, the error is
    "0 %", and the comment says the bristle dynamics are not exported (it is not static)."""
    from fricid.export import mjcf_text

    dahl = FittedModel.from_values(
        "dahl",
        {"sigma_0": 1000.0, "tau_c": 0.5, "alpha": 1.0, "sigma_2": 0.1},
        operating_range={"velocity": [-1.0, 1.0]},
    )
    text = mjcf_text(dahl)
    assert "(0 % of the RMS friction" in text
    assert "velocity shape" not in text and "static model" not in text
    assert "steady state of a Dahl model (dynamic)" in text
    assert 'frictionloss="0.5' in text
