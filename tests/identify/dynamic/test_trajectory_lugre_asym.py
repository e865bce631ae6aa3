"""LuGre with its levels per direction (``lugre_asym``) from a trajectory.

The logs come from the independent simulator of ``benchmarks/bench_lugre.py``
(``benchmarks/_lugre_truth.py``: its own RK4 joint and PD drive), the backward Coulomb and
break-away levels ``neg`` times the forward ones. Fitted with the symmetric ``lugre`` such a
joint's gravity takes up half the difference (``test_trajectory_direction.py``: p_x -0.776
for -0.591, outside its interval); ``lugre_asym`` was refused ("unknown model").
"""

from __future__ import annotations

import dataclasses
import sys
import warnings

import numpy as np
import pytest
from tests._paths import REPO
from typer.testing import CliRunner

from fricid.cli import app
from fricid.errors import ConfigError
from fricid.fitted import FittedModel
from fricid.identify import fit
from fricid.identify.dynamic.trajectory import fit_trajectory
from fricid.identify.trajectory_check import predict_trajectory
from fricid.io import read_rawlog
from fricid.samples import RawLog

sys.path.insert(0, str(REPO / "benchmarks"))
import _lugre_truth as lt


def simulated(truth: str, kind: str, neg: float, seed: int, path):
    t = dataclasses.replace(lt.TRUTHS[truth], neg=neg)
    log = lt.simulate(t, kind, 10.0, 1000.0, 2**20, seed)
    return read_rawlog(lt.write_log(log, path, t, {})), t


def per_direction_truth(t) -> dict[str, float]:
    """The truth in ``lugre_asym``'s names (the simulator's sigma_2 is one for both ways)."""
    base = t.fricid_names()
    out = dict(base)
    for name, back in (("sigma_2", 1.0), ("tau_c", t.neg), ("tau_s", t.neg)):
        out[f"{name}_pos"], out[f"{name}_neg"] = base[name], back * base[name]
    return out


def quiet_fit(log, model: str, seed: int):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit(log, model, seed=seed)


def covers(fitted: FittedModel, truth: dict[str, float], names) -> dict[str, bool]:
    joint = fitted.provenance["trajectory"]["joint"]
    out = {}
    for n in names:
        if n in fitted.parameters:
            lo, hi = fitted.parameters[n].ci95
        else:
            lo, hi = joint[n]["ci95_low"], joint[n]["ci95_high"]
        out[n] = bool(lo <= truth[n] <= hi)
    return out


@pytest.mark.slow  # 13 s under the default run's load: a lugre_asym fit with its checks
def test_a_joint_weaker_backwards_gets_both_levels_and_its_gravity(tmp_path):
    """The log on which the symmetric fit's p_x missed (geared joint, 30 % weaker backwards,
    PD-tracked 0.3 rad chirp, seed 3): each level and the gravity within their intervals,
    the levels told apart, no direction caveat, and the coverage caveat giving the
    per-direction fits' own coverage."""
    log, t = simulated("geared", "chirp_pd", 0.7, 3, tmp_path / "a.csv")
    fitted = quiet_fit(log, "lugre_asym", 3)
    truth = per_direction_truth(t)
    held = covers(fitted, truth, ("tau_c_pos", "tau_c_neg", "sigma_2_pos", "sigma_2_neg"))
    held |= covers(fitted, truth, ("inertia", "p_x", "p_y"))
    assert all(held.values()), held
    pos, neg = (fitted.parameters[n].ci95 for n in ("tau_c_pos", "tau_c_neg"))
    assert neg[1] < pos[0]  # told apart
    info = fitted.provenance["trajectory"]
    caveats = info.get("caveats", [])
    assert not any("by direction" in c for c in caveats), caveats
    assert any("with the levels per direction" in c and "bench_direction.py" in c for c in caveats)
    assert "in each direction" in info["passivity"]["condition"]
    # held out on the next seed's log: the per-direction law along it (the held-out check's
    # law table knows it)
    other, _ = simulated("geared", "chirp_pd", 0.7, 4, tmp_path / "b.csv")
    pred = predict_trajectory(fitted, other)
    err = (pred.torque_filtered - pred.predicted_filtered)[pred.sliding]
    assert np.sqrt(np.nanmean(err**2)) < 0.01  # 1 % of the 1.2 N m level (0.0038 measured)


@pytest.mark.slow
def test_a_symmetric_joint_gets_the_same_levels_both_ways(tmp_path):
    """No difference invented: on a symmetric joint (geared, trapezoid over its range) each
    direction's levels hold the one truth, and their intervals overlap. (With the pooled
    sigma_2 factor, 1.42, sigma_2_neg's interval fell short of the truth here; the trapezoid
    rests, and the factor of resting logs, 1.63, holds it.)"""
    log, t = simulated("geared", "trapezoid_pd", 1.0, 5, tmp_path / "a.csv")
    fitted = quiet_fit(log, "lugre_asym", 5)
    truth = per_direction_truth(t)
    held = covers(fitted, truth, ("tau_c_pos", "tau_c_neg", "sigma_2_pos", "sigma_2_neg"))
    assert all(held.values()), held
    pos, neg = (fitted.parameters[n].ci95 for n in ("tau_c_pos", "tau_c_neg"))
    assert max(pos[0], neg[0]) < min(pos[1], neg[1])


@pytest.mark.slow
def test_the_mirrored_log_swaps_the_per_direction_levels(tmp_path):
    """Mirroring the joint (q, v, torque -> -q, -v, -torque) swaps the directions: the
    forward levels of one fit are the backward levels of the other, and p_x changes sign."""
    log, _ = simulated("slow_stribeck", "trapezoid_pd", 0.8, 4, tmp_path / "a.csv")
    mirror = RawLog(
        time=log.time,
        position=-log.position,
        velocity=-log.velocity,
        torque=-log.motor_torque,
        temperature=log.temperature,
    )
    a, b = (quiet_fit(x, "lugre_asym", 4) for x in (log, mirror))
    for name in ("tau_c", "sigma_2"):
        for here, there in (("pos", "neg"), ("neg", "pos")):
            pa, pb = a.parameters[f"{name}_{here}"], b.parameters[f"{name}_{there}"]
            assert pb.value == pytest.approx(pa.value, abs=0.25 * pa.stderr), name
    ja, jb = (f.provenance["trajectory"]["joint"] for f in (a, b))
    assert jb["p_x"]["value"] == pytest.approx(-ja["p_x"]["value"], abs=0.25 * ja["p_x"]["stderr"])


def test_per_direction_lugre_takes_the_filtered_route_only():
    t = np.arange(2000) * 1e-3
    log = RawLog(
        time=t,
        position=np.sin(t),
        velocity=np.cos(t),
        torque=np.cos(t),
        temperature=np.full(t.size, 25.0),
    )
    with pytest.raises(ConfigError, match="lugre_asym is identified by the filtered route only"):
        fit_trajectory(log, "lugre_asym", route="two_stage")
    with pytest.raises(ConfigError, match="a trajectory identifies lugre, lugre_asym, dahl"):
        fit_trajectory(log, "dahl_asym")


@pytest.mark.slow
def test_the_command_line_fits_and_exports_it(tmp_path):
    """``fricid fit --trajectory --model lugre_asym`` prints both sets, and the MJCF export
    says that MuJoCo's LuGre has one level (the bristles not exported)."""
    simulated("geared", "chirp_pd", 0.7, 3, tmp_path / "a.csv")
    model, xml = tmp_path / "m.json", tmp_path / "m.xml"
    runner = CliRunner()
    args = ["fit", "--trajectory", str(tmp_path / "a.csv"), "--model", "lugre_asym"]
    out = runner.invoke(app, [*args, "-o", str(model), "--quiet"])
    assert out.exit_code == 0, out.output
    assert "tau_c_pos:" in out.stdout and "tau_c_neg:" in out.stdout
    assert "sigma_2_neg:" in out.stdout
    args = ["export", str(model), "--to", "mjcf", "--allow-undetermined", "-o", str(xml)]
    done = runner.invoke(app, args)
    assert done.exit_code == 0, done.output
    text = xml.read_text()
    assert "has one level for both directions" in text
    assert "the direction asymmetry" in text  # lost in the projection, and said
    assert "N m forwards at" in text and "N m backwards at" in text  # each break-away
    out = tmp_path / "report"
    done = runner.invoke(app, ["report", str(model), str(tmp_path / "a.csv"), "-o", str(out)])
    assert done.exit_code == 0, done.output
    assert r"\_pos: moving forwards, v \>= 0" in (out / "report.md").read_text()


def test_the_passivity_record_names_the_direction_that_fails():
    """A new user read "margin -3.23 ... in each direction" and could not tell which."""
    from fricid.identify.dynamic._outcome import passivity
    from fricid.models import lugre

    values = [1e4, 1.0, 0.2, 0.5, 0.8, 0.1, 1.0, 0.001, 0.35, 0.56]  # backwards: no damping
    nan = [float("nan")] * 10
    record = passivity(list(lugre.ASYM_NAMES), values, nan, nan)
    assert not record["passive"]
    assert "forwards 0.333, backwards -0.993 N m s/rad" in record["condition"]


def test_a_rate_bias_of_a_value_not_told_from_zero_is_given_in_its_unit():
    """ "p_x -57 % (0.58 se)" for p_x of -0.001 N m said nothing; the bias in N m does."""
    from types import SimpleNamespace

    from fricid.identify.dynamic._outcome import RateBiasWarning, warn_rate_bias

    stage = SimpleNamespace(
        names=["p_x", "p_y"], values=np.array([-0.001, 1.5]), stderr=np.array([0.002, 0.001])
    )
    rows = {
        "p_x": {"bias": 0.0012, "relative": -1.2, "scale": "linear"},
        "p_y": {"bias": 0.0009, "relative": 0.0006, "scale": "linear"},
    }
    with pytest.warns(RateBiasWarning) as caught:
        warn_rate_bias(stage, {"parameters": rows, "log_rate": 1000.0, "quantised": None})
    text = str(caught[0].message)
    assert "p_x +0.0012 N m (0.6 se; it is -0.001)" in text
    assert "p_y +0.06 % (0.9 se)" in text


@pytest.mark.slow
def test_a_log_that_never_moves_backwards_leaves_the_backward_set_not_identified():
    """Torque that only ever pushes forwards: the forward set is identified, the backward one
    is said not to be, and the passivity line says what it rests on (a margin from the
    backward set's arbitrary values said "NOT passive" alone)."""
    from fricid.cli.trajectory import trajectory_text
    from fricid.models import lugre

    n, dt = 10000, 1e-3
    t = np.arange(n) * dt
    theta = np.array([2e4, 3.0, 0.4, 1.2, 1.8, 0.05, 2.0, 0.4, 0.84, 1.26])
    tau = 2.5 + np.sin(2 * np.pi * 0.5 * t) + 0.8 * np.sin(2 * np.pi * 1.7 * t)
    sim = lugre.simulate_joint(theta, 0.05, 0.0, 0.5, dt, tau)
    count = 2 * np.pi / 2**20
    q = np.round(sim["position"] / count) * count
    noise = 0.01 * np.random.default_rng(0).standard_normal(n)
    log = RawLog(
        time=t,
        position=q,
        velocity=np.concatenate([[0.0], np.diff(q) / dt]),
        torque=tau + noise,
        temperature=np.full(n, 25.0),
    )
    assert not np.any(sim["velocity"] < -0.02)  # never slides backwards
    fitted = quiet_fit(log, "lugre_asym", 0)
    for name in ("sigma_2_neg", "tau_c_neg", "tau_s_neg"):
        assert fitted.parameters[name].not_determined, name
    for name in ("sigma_2_pos", "tau_c_pos"):
        p = fitted.parameters[name]
        assert (
            not p.not_determined and p.ci95[0] <= theta[lugre.ASYM_NAMES.index(name)] <= p.ci95[1]
        )
    line = next(ln for ln in trajectory_text(fitted).splitlines() if "passivity:" in ln)
    assert "sigma_2_neg, tau_c_neg, tau_s_neg, not determined" in line
    # one side identified: a prediction backwards is said to be on the other side (it was
    # recorded as both, and -1 rad/s passed without a word)
    assert fitted.provenance["directions"] == [1]
    (out,) = fitted.range_check(np.array([[-1.0, 0.0, 25.0]]))
    assert out.kind == "side"
