"""Dahl from a trajectory, through the one ``fit`` and ``fricid fit --trajectory``."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.errors import ConfigError
from fricid.fitted import FittedModel
from fricid.identify import fit
from fricid.io import write_rawlog
from fricid.models import dahl
from fricid.samples import RawLog

#: Dahl's truth: sigma_0 [N m/rad], tau_c [N m], alpha, sigma_2 [N m s/rad] (a transition
#: over tau_c / sigma_0 = 1.3 mrad, which a 1 kHz log of a slow multi-sine resolves).
THETA = np.array([300.0, 0.4, 1.0, 0.15])
J, P_X, P_Y = 0.01, 0.3, 0.1


def dahl_log(duration: float = 4.0, rate: float = 500.0, noise: float = 0.005) -> RawLog:
    """A prescribed multi-sine with the torque that drives it through Dahl friction and
    gravity, by inverse dynamics on a grid ten times finer; each logged torque is its mean
    over the period after the sample (a zero-order-hold drive), plus white noise."""
    up = 10
    fine = rate * up
    t = np.arange(round(duration * fine) + 1) / fine
    rng = np.random.default_rng(5)
    q, v, a = (np.zeros_like(t) for _ in range(3))
    for f, phase in zip((0.2, 0.5, 1.1, 2.3), rng.uniform(0, 2 * np.pi, 4), strict=True):
        w = 2 * np.pi * f
        q += 0.075 * np.sin(w * t + phase)
        v += 0.075 * w * np.cos(w * t + phase)
        a -= 0.075 * w**2 * np.sin(w * t + phase)
    friction, _ = dahl.simulate(THETA, v, 1.0 / fine, np.sign(v[0]) * THETA[1])
    u = J * a + friction - (P_X * np.cos(q) - P_Y * np.sin(q))
    n = (t.size - 1) // up
    k = np.arange(n) * up
    torque = u[1:].reshape(n, up).mean(axis=1) + noise * rng.standard_normal(n)
    return RawLog(
        time=t[k],
        position=q[k],
        velocity=v[k],
        temperature=np.full(n, 25.0),
        torque=torque,
        source="dahl.csv",
    )


@pytest.mark.slow  # 2.6 s measured under load (numba's first Dahl call included)
def test_dahl_parameters_recovered_from_a_trajectory():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing to warn about on a clean log
        fitted = fit(dahl_log(), "dahl")
    assert fitted.model == "dahl" and fitted.converged
    info = fitted.provenance["trajectory"]
    assert info["route"] == "filtered" and set(info["routes"]) == {"regression", "filtered"}
    for (name, p), truth in zip(fitted.parameters.items(), THETA, strict=True):
        assert p.value == pytest.approx(truth, rel=0.02), name
        assert p.ci95[0] < p.value < p.ci95[1] and not p.not_determined, name
    for name, truth in (("inertia", J), ("p_x", P_X), ("p_y", P_Y)):
        assert info["joint"][name]["value"] == pytest.approx(truth, rel=0.03), name


def test_dahl_takes_the_filtered_route_only():
    with pytest.raises(ConfigError, match="dahl is identified by the filtered route only"):
        fit(dahl_log(duration=2.0), "dahl", settings={"route": "two_stage"})


def test_cli_fits_dahl_from_a_trajectory(tmp_path):
    path = write_rawlog(dahl_log(duration=3.0), tmp_path / "dahl.csv")
    out = tmp_path / "dahl.json"
    result = CliRunner().invoke(
        app, ["fit", str(path), "--trajectory", "--model", "dahl", "--out", str(out)]
    )
    assert result.exit_code == 0, result.output
    assert "[[Trajectory]]" in result.output
    fitted = FittedModel.load(out)
    assert fitted.model == "dahl"
    for name, truth in zip(dahl.PARAM_NAMES, THETA, strict=True):
        assert fitted.params[name] == pytest.approx(truth, rel=0.02), name
