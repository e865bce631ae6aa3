"""The one public ``fit``: an explicit signature, an explicit table of the kinds of
identification, one meaning for ``method``, and settings checked per kind; and the rooms it
dispatches to stay small enough to read."""

from __future__ import annotations

import inspect
from pathlib import Path

import numpy as np
import pytest

import fricid.identify as identify
from _paths import SRC
from fricid.errors import ConfigError
from fricid.identify import KINDS, fit, kind_of
from fricid.samples import FrictionSamples, RawLog


def _samples() -> FrictionSamples:
    v = np.geomspace(0.01, 1.0, 10)
    v = np.concatenate([v, -v])
    f = np.sign(v) * (0.2 + 0.1 * np.exp(-((v / 0.05) ** 2))) + 0.05 * v
    return FrictionSamples(velocity=v, load=None, temperature=None, friction=f)


def test_fit_has_an_explicit_signature():
    sig = inspect.signature(identify.fit)
    kinds = {p.kind for p in sig.parameters.values()}
    assert inspect.Parameter.VAR_KEYWORD not in kinds
    assert inspect.Parameter.VAR_POSITIONAL not in kinds
    assert not hasattr(identify.fit, "__wrapped__")
    assert list(sig.parameters)[:3] == ["data", "model", "method"]
    assert {"fixed", "bounds", "options", "settings", "loss", "weights"} <= set(sig.parameters)


def test_the_kind_is_decided_by_the_data_and_the_model():
    s = _samples()
    log = RawLog(
        time=np.arange(5) * 0.01,
        position=np.zeros(5),
        velocity=np.zeros(5),
        torque=np.zeros(5),
        temperature=np.full(5, 25.0),
    )
    assert set(KINDS) == {"analytic", "learned", "dynamic", "auto", "arm"}
    assert kind_of(s, "stribeck") == "analytic"
    assert kind_of(s, "stribeck_temp_asym") == "analytic"
    assert all(kind_of(s, m) == "learned" for m in ("rbf", "hybrid", "gp"))
    assert kind_of(s, " Auto ") == "auto"
    assert kind_of(log, "lugre") == "dynamic"
    with pytest.raises(ConfigError, match=r"FrictionSamples, a RawLog .* or a RobotLog"):
        kind_of([1, 2, 3], "stribeck")


def test_settings_are_checked_per_kind():
    s = _samples()
    with pytest.raises(ConfigError, match="analytic identification takes no settings"):
        fit(s, "coulomb_viscous", settings={"network": {}})
    with pytest.raises(ConfigError, match=r"model 'gp' takes inputs, max_points, n_restarts"):
        fit(s, "gp", settings={"n_centers": 3})
    with pytest.raises(ConfigError, match="auto identification does not take fixed"):
        fit(s, "auto", fixed={"f_c": 0.1})


def test_method_has_one_meaning():
    s = _samples()
    assert fit(s, "coulomb_viscous").optimizer.method == "lm"  # the default optimiser
    with pytest.raises(ConfigError, match="trains with method lsq, bas, ga; got 'lm'"):
        fit(s, "rbf", "lm")
    with pytest.raises(ConfigError, match="trains with method ml"):
        fit(s, "gp", "bas")


def test_the_rooms_stay_small():
    """No identification folder over 15 modules, no module of fricid over 600 lines."""
    root = SRC / "fricid" / "identify"
    for folder in (root, *(p for p in root.iterdir() if p.is_dir() and p.name[0] != "_")):
        assert len(list(folder.glob("*.py"))) <= 15, folder
    long = [
        f"{p}: {n}"
        for p in sorted((SRC / "fricid").rglob("*.py"))
        if (n := len(p.read_text(encoding="utf-8").splitlines())) > 600
    ]
    assert not long, long


def test_the_trajectory_route_is_reached_through_fit():
    """A RawLog goes to dynamic identification, with its settings checked there."""
    log = RawLog(
        time=np.arange(5) * 0.01,
        position=np.zeros(5),
        velocity=np.zeros(5),
        torque=np.zeros(5),
        temperature=np.full(5, 25.0),
    )
    with pytest.raises(ConfigError, match="dynamic identification takes route"):
        fit(log, "lugre", settings={"network": {}})
    with pytest.raises(ConfigError, match="dynamic identification does not take fixed"):
        fit(log, "lugre", fixed={"tau_c": 1.0})


def test_no_test_module_is_named_for_an_issue():
    """Tests live by the module they test (tests/<layer>/...), none at the top of tests/."""
    tests = Path(__file__).resolve().parents[1]
    assert not list(tests.glob("test_*.py"))
