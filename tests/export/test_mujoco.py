"""The MJCF export checked in MuJoCo (issue 16): the fragment `fricid export --to mjcf` writes,
built into a one-joint model and driven by the same torque as a Python joint under the true
friction; LuGre friction through MuJoCo's dcmotor actuator."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.control import fitted_law
from fricid.control.plant import drive
from fricid.errors import ConfigError
from fricid.export import mjcf_text
from fricid.export.mjcf import MUJOCO_STRIBECK_EXPONENT, lugre_mapping
from fricid.export.mujoco_check import one_joint_xml, run_torque
from fricid.fitted import FittedModel
from fricid.models import lugre


@pytest.fixture
def mujoco():
    """The optional mujoco package; the tests that run MuJoCo skip without it."""
    return pytest.importorskip(
        "mujoco", reason="the MuJoCo checks need the optional mujoco package (pip install mujoco)"
    )


runner = CliRunner()
J = 0.01
RANGE = {"velocity": [0.01, 2.0], "load": [0, 0], "temperature": [25, 25]}
#: A LuGre joint with MuJoCo's Stribeck exponent (2): passive (sigma_1 0.5 <= 0.6).
LUGRE = dict(sigma_0=1e3, sigma_1=0.5, sigma_2=0.1, tau_c=0.3, tau_s=0.5, w_s=0.05, delta=2.0)


def lugre_model(**changes) -> FittedModel:
    return FittedModel.from_values(
        "lugre", {**LUGRE, **changes}, operating_range={"velocity": [-2.0, 2.0]}
    )


def theta(params: dict) -> np.ndarray:
    return np.array([params[k] for k in lugre.PARAM_NAMES])


def sine(dt: float, seconds: float, amplitude: float) -> np.ndarray:
    return amplitude * np.sin(2 * np.pi * np.arange(round(seconds / dt)) * dt)


def rms(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.mean((a - b) ** 2)))


@pytest.mark.slow  # 3 s measured under load (default run kept short)
def test_cli_export_runs_in_mujoco_and_tracks_the_karnopp_joint(tmp_path, mujoco):
    """Coulomb-viscous truth, exported exactly: MuJoCo's trajectory follows the Python joint's;
    frictionloss is a soft constraint, and the export's stiffer solimpfriction follows it
    closer than MuJoCo's default."""
    cv = FittedModel.from_values(
        "coulomb_viscous", {"f_c": 0.3, "beta": 0.1}, operating_range=RANGE
    )
    cv.save(tmp_path / "cv.json")
    out = tmp_path / "cv.mjcf"
    res = runner.invoke(
        app,
        ["export", str(tmp_path / "cv.json"), "--to", "mjcf", "--joint", "elbow", "-o", str(out)],
    )
    assert res.exit_code == 0, res.output
    fragment = out.read_text()
    assert "soft constraint" in fragment
    dt = 1e-3
    u = sine(dt, 2.0, 0.6)  # twice the Coulomb friction: stick, slip, stick
    ref = drive(u, dt, J, law=fitted_law(cv))
    exported = run_torque(one_joint_xml(fragment, J, dt), u)
    default = {"solimpfriction": "0.9 0.95 0.001"}  # MuJoCo's own
    soft = run_torque(one_joint_xml(fragment, J, dt, joint_overrides=default), u)
    span = np.ptp(ref["position"])
    assert span > 0.3
    assert rms(exported["position"], ref["position"]) < 0.005 * span
    assert rms(exported["position"], ref["position"]) < 0.6 * rms(soft["position"], ref["position"])
    # without frictionloss the joint runs away: the check sees friction at all
    free = run_torque(one_joint_xml('<joint name="elbow" />', J, dt), u)
    assert rms(free["position"], ref["position"]) > 0.1 * span


def test_dcmotor_lugre_steady_state_has_exponent_two(mujoco):
    """Held at constant velocity, MuJoCo's bristle state settles to g(v) / sigma_0 with a
    Stribeck exponent of 2 (the basis of MUJOCO_STRIBECK_EXPONENT)."""
    fragment = mjcf_text(lugre_model(), joint="j")
    model = mujoco.MjModel.from_xml_string(one_joint_xml(fragment, J, 1e-3))
    data = mujoco.MjData(model)
    assert model.na == 1  # the bristle state
    th = theta(LUGRE)
    for v in (0.02, 0.05, 0.1):
        mujoco.mj_resetData(model, data)
        for _ in range(500):
            data.qvel[0] = v
            mujoco.mj_step(model, data)
        expected = lugre.stribeck_curve(th, np.array([v]))[0] / th[0]
        np.testing.assert_allclose(data.act[0], expected, rtol=1e-6)
    assert MUJOCO_STRIBECK_EXPONENT == 2.0


def test_lugre_export_in_mujoco_tracks_the_python_lugre_joint(mujoco):
    fragment = mjcf_text(lugre_model(), joint="elbow")
    root = ET.fromstring(f"<r>{fragment}</r>")
    motor = root.find("actuator/dcmotor")
    assert motor.get("input") == "none" and motor.get("joint") == "elbow"
    assert root.find("joint").get("damping") == "0.1"
    assert "mapping is exact" in fragment and "MuJoCo < 4.0" in fragment
    dt = 2e-4
    u = sine(dt, 1.0, 0.8)
    ref = drive(u, dt, J, lugre_theta=theta(LUGRE))
    mj = run_torque(one_joint_xml(fragment, J, dt), u)
    span = np.ptp(ref["position"])
    assert rms(mj["position"], ref["position"]) < 0.01 * span
    # the same joint without its bristle damping sigma_1 is measurably further away
    mj0 = run_torque(one_joint_xml(mjcf_text(lugre_model(sigma_1=0.0), joint="elbow"), J, dt), u)
    assert rms(mj0["position"], ref["position"]) > 2 * rms(mj["position"], ref["position"])


def test_lugre_export_maps_another_exponent_and_states_the_error():
    m = lugre_mapping(lugre_model(delta=1.0))
    assert m.w_s != LUGRE["w_s"] and 0 < m.rms_error < 0.05 * m.rms_friction
    text = mjcf_text(lugre_model(delta=1.0))
    assert "w_s refit to" in text and "steady-state error RMS" in text
    exact = lugre_mapping(lugre_model())
    assert exact.rms_error == 0.0 and exact.w_s == LUGRE["w_s"]
    assert exact.static_rms_error > 0  # the static fallback loses the Stribeck peak


def test_lugre_export_says_whether_the_model_is_passive():
    """A LuGre model that is not passive (sigma_1 above 4 sigma_2 tau_c / (tau_s - tau_c)) is
    said so in the MJCF; the dcmotor's own 'passive' (no control input) no longer reads as an
    assurance about the friction."""
    said = " ".join(mjcf_text(lugre_model()).split())
    assert "the LuGre model is passive (margin 0.1 N m s/rad)" in said
    assert "actuator, passive" not in said and "without a control input" in said
    loud = " ".join(mjcf_text(lugre_model(sigma_1=3.5)).split())
    assert "the LuGre model is NOT passive (margin -2.9 N m s/rad" in loud
    flat = " ".join(mjcf_text(lugre_model(tau_s=0.3)).split())
    assert "passive for any sigma_1" in flat


def test_fragment_checks():
    with pytest.raises(ConfigError, match="one <joint>"):
        one_joint_xml("<actuator/>")
    with pytest.raises(ConfigError, match="does not parse"):
        one_joint_xml("<joint")
    bad = '<joint name="a"/><actuator><dcmotor joint="b" lugre="1 0 1 1 1"/></actuator>'
    with pytest.raises(ConfigError, match="not on"):
        one_joint_xml(bad)


def test_cli_export_of_a_lugre_model_states_the_mapping(tmp_path, monkeypatch):
    """`fricid export --to mjcf` of a LuGre model file: the dcmotor in the file, and what the
    exponent mapping and the static fallback cost on stderr. (Loading a 'lugre' file needs
    the model registered; here the loader is stubbed.)"""
    path = tmp_path / "lugre.json"
    path.write_text("{}")
    monkeypatch.setattr(FittedModel, "load", classmethod(lambda cls, p: lugre_model(delta=1.0)))
    out = tmp_path / "lugre.mjcf"
    res = runner.invoke(
        app, ["export", str(path), "--to", "mjcf", "-o", str(out), "--no-timestep-check"]
    )
    assert res.exit_code == 0, res.output
    assert "<dcmotor" in out.read_text()
    notes = " ".join(res.stderr.split())
    assert "note: MuJoCo's Stribeck exponent is 2, this model's 1" in notes
    assert "without dcmotor (MuJoCo < 4.0)" in notes
    res = runner.invoke(app, ["export", str(path), "--to", "mjcf", "--max-loss", "0.001"])
    assert res.exit_code == 2 and "cannot represent this model's exponent" in res.output


def test_lugre_export_refuses_bad_names_and_values():
    from fricid.export import ExportError

    with pytest.raises(ExportError):
        mjcf_text(lugre_model(), joint='a"b><x')
    with pytest.raises(ExportError, match="finite"):
        mjcf_text(lugre_model(sigma_0=float("nan")))
    with pytest.raises(ExportError, match="needs the parameters"):
        mjcf_text(FittedModel.from_values("lugre", {"sigma_0": 1.0}))


def test_a_trajectory_model_s_comment_names_its_estimator_and_residual():
    """A model identified from a trajectory: the comment names the estimator and says the
    fit's error is of the residual the estimator fitted (low-passed, or a simulation's), not
    the torque error on the log (a new user compared it with the report's, 15x larger)."""
    fitted = lugre_model()
    fitted.metrics = {"rmse": 0.00205, "max_abs_error": 0.0068}
    fitted.provenance = {
        "trajectory": {"estimator": {"name": "DIDIM output error <script>", "bias": "x"}},
        "source": "chirp.csv",
    }
    text = mjcf_text(fitted)
    assert "estimator: DIDIM output error" in text and "<script>" not in text
    assert "of the residual the estimator fitted" in text
    static = FittedModel.from_values(
        "stribeck",
        dict(tau_c=0.1, tau_s=0.2, w_s=0.1, tau_v=0.01, delta=1.0),
        operating_range={"velocity": [-2.0, 2.0]},
    )
    static.metrics = {"rmse": 0.01}
    assert "estimator" not in mjcf_text(static)


def test_inputs_the_model_does_not_read_are_not_given_a_range():
    """A law of velocity alone: its projection comment says load and temperature are not read
    (an arm fit's export had said "temperature 0 to 0 degC")."""
    fitted = FittedModel.from_values(
        "stribeck",
        dict(tau_c=0.1, tau_s=0.2, w_s=0.1, tau_v=0.01, delta=1.0),
        operating_range={"velocity": [-2.0, 2.0]},
    )
    text = mjcf_text(fitted)
    assert "load: not read by the model, temperature: not read by the model" in text
    assert "0 to 0 degC" not in text and "temperature 0 degC" not in text
