"""One BLAS thread on every least-squares path (:mod:`fricid.optim._threads`).

Outside a fit BLAS keeps the limit it had (here set to two threads, so a path that forgot the
limit shows two); inside ``minimize``'s least-squares solvers, ``fit``, varpro, the profile
intervals, ``validate`` and ``select``, threadpoolctl reports one. Each probe runs inside the
computation: an optimiser callback, or a wrapper around a function the computation calls.
"""

from __future__ import annotations

import importlib
import warnings

import numpy as np
import pytest
from threadpoolctl import threadpool_limits

from fricid.errors import FricidWarning
from fricid.identify import fit, validate
from fricid.identify.static import profile as profile_mod
from fricid.identify.static import select as select_mod
from fricid.optim import blas_threads, minimize, one_blas_thread
from fricid.samples import FrictionSamples

#: ``fricid.identify.validate`` the module (the package's attribute of that name is the function).
validate_mod = importlib.import_module("fricid.identify.validate")


@pytest.fixture
def two_threads():
    """BLAS limited to two threads around the test (skipped where it cannot use two)."""
    with threadpool_limits(limits=2, user_api="blas"):
        if blas_threads() != 2:
            pytest.skip(f"BLAS cannot use two threads here (reports {blas_threads()})")
        yield
        assert blas_threads() == 2, "the limit outside the fit was not restored"


@pytest.fixture(scope="module")
def samples() -> FrictionSamples:
    """A Stribeck curve on 24 velocities, both directions, with 1 % noise."""
    rng = np.random.default_rng(0)
    v = np.repeat(np.geomspace(0.01, 2.0, 12), 2) * np.tile([1.0, -1.0], 12)
    a = np.abs(v)
    f = np.sign(v) * (0.5 + 0.3 * np.exp(-((a / 0.1) ** 2)) + 0.2 * a)
    f = f + 0.01 * rng.standard_normal(v.size)
    return FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=f)


class Probe:
    """Records the BLAS thread count each time it is called (the first 5 calls)."""

    def __init__(self) -> None:
        self.seen: list[int | None] = []

    def __call__(self, *args, **kwargs) -> None:
        if len(self.seen) < 5:
            self.seen.append(blas_threads())

    def check(self) -> None:
        assert self.seen, "the probe never ran inside the computation"
        assert set(self.seen) == {1}, f"BLAS threads seen inside: {self.seen}"


def wrap(probe: Probe, func):
    def wrapper(*args, **kwargs):
        probe()
        return func(*args, **kwargs)

    return wrapper


def quiet(func, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FricidWarning)
        return func(*args, **kwargs)


@pytest.mark.parametrize("method", ["lm", "trf", "lm_minpack", "bas+lm"])
def test_minimize_least_squares_runs_on_one_blas_thread(two_threads, method):
    target = np.array([0.3, -0.2])
    probe = Probe()
    minimize(
        None,
        [(-1.0, 1.0), (-1.0, 1.0)],
        method,
        seed=0,
        max_evals=400,
        residuals=lambda X: np.atleast_2d(X) - target,
        callback=probe,
    )
    probe.check()


@pytest.mark.parametrize("method", ["lm", "varpro"])
def test_fit_runs_on_one_blas_thread(two_threads, samples, method):
    probe = Probe()
    quiet(fit, samples, "stribeck", method, callback=probe, intervals="none")
    probe.check()


def test_profile_intervals_run_on_one_blas_thread(two_threads, samples, monkeypatch):
    probe = Probe()
    monkeypatch.setattr(profile_mod, "least_squares", wrap(probe, profile_mod.least_squares))
    quiet(fit, samples, "stribeck", "lm", intervals="profile")
    probe.check()


def test_validate_runs_on_one_blas_thread(two_threads, samples, monkeypatch):
    probe = Probe()
    monkeypatch.setattr(validate_mod, "fit", wrap(probe, validate_mod.fit))
    quiet(validate, samples, "coulomb_viscous", "kfold:3")
    probe.check()


class Stop(Exception):
    """Ends a computation once the probe has run inside it."""


def test_select_runs_on_one_blas_thread(two_threads, samples, monkeypatch):
    probe = Probe()

    def first_validation(*args, **kwargs):
        probe()
        raise Stop

    monkeypatch.setattr(select_mod, "validate", first_validation)
    with pytest.raises(Stop):
        quiet(select_mod.select, samples, "lm", scheme="kfold:3")
    probe.check()


def test_nested_uses_share_one_limit_and_restore_it(two_threads):
    """The outermost use sets the limit and restores it; an inner exit does not lift it."""
    with one_blas_thread():
        with one_blas_thread():
            assert blas_threads() == 1
        assert blas_threads() == 1
    assert blas_threads() == 2
