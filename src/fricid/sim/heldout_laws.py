"""Held-out friction laws (issue 15): three kinds of truth fricid was not tuned on, with the
noise of their averaged samples known, so the floor of a held-out error is known.

Each :class:`HeldOutLaw` is a true function ``law(velocity, load, temperature)`` (signed
friction [N m], odd-ish in velocity as the kind says), a sampling design (the training grid),
the standard deviation ``noise`` [N m] of the averaged samples, and two draws per seed: the
training samples (the grid plus Gaussian noise) and a held-out set (random points inside the
grid's box, with their own noise). Held-out RMSE / ``noise`` is then 1.0 for a model equal to
the truth, and larger for any other.

The three kinds differ on purpose from the simulator presets (:mod:`fricid.sim.presets`:
``paper1``'s :class:`~fricid.sim.laws.LoadTemperatureLaw` and ``paper2``'s Stribeck law) and
from every fricid model family, so fits are tested under honest misspecification:

``"grid"``
    Paper-1-shaped: combined samples (direction 0, eq. 11 of the BAS-RBFNN paper) on a grid of
    12 velocities (0.15-45 deg/s, geometric) x 11 loads (0.12-0.26 N m) x 14 temperatures
    (10-49 degC), 1848 points. Bittencourt-style [BG]: a Coulomb level that grows with |load|
    and falls linearly with temperature, a load-dependent Stribeck excess with a Gaussian
    shape (exponent 2), and a viscous term ``beta(T) |v|^0.85`` whose coefficient falls
    exponentially with temperature (the lubricant thins). Noise 0.6 mN m.
``"asym_arrhenius"``
    Asymmetric Stribeck law (different levels and Stribeck velocities per direction) with an
    Arrhenius viscous coefficient ``beta(T) = beta_ref exp(E/R (1/T - 1/T_ref))`` (T in
    kelvin; the Andrade-Arrhenius law of oil viscosity), per-direction samples at 15
    velocities (0.005-3 rad/s) x 2 directions x 5 temperatures (15-55 degC), 150 points; load
    not measured. Noise 2 mN m.
``"sigmoid"``
    The Franka-like sigmoid of Gaz et al. (2019) [GZ], ``phi1 / (1 + exp(-phi2 (v + phi3))) -
    phi1 / (1 + exp(-phi2 phi3))`` (zero at rest, asymmetric levels through the offset
    ``phi3``), with a Coulomb level ``phi1 = a + b |load|`` and a small viscous term;
    per-direction samples at 18 velocities (0.01-2 rad/s) x 2 directions x 15 loads
    (-3..3 N m), 540 points; temperature not measured. Noise 1.5 mN m.

Seeds: :data:`TUNING_SEEDS` (0-99) are the draws a developer may look at while choosing
defaults (the cross-validation grids of :mod:`fricid.identify.learned._rbf_select` were checked on
seeds 0-2); :data:`REPORTING_SEEDS` (1001-1003) are the draws ``benchmarks/bench_floor.py``
reports, never used to choose anything. The two sets are disjoint (:func:`draw` refuses
neither; the separation is a convention the benchmark keeps).

References
----------
[BG] A. C. Bittencourt, S. Gunnarsson, "Static friction in a robot joint: modeling and
     identification of load and temperature effects", J. Dyn. Sys., Meas., Control 134(5),
     2012.
[GZ] C. Gaz, M. Cognetti, A. Oliva, P. Robuffo Giordano, A. De Luca, "Dynamic identification
     of the Franka Emika Panda robot with retrieval of feasible parameters using
     penalty-based optimization", IEEE RA-L 4(4), 2019, eq. 7 (the sigmoid friction).
[AN] E. N. da C. Andrade, "The viscosity of liquids", Nature 125, 1930 (viscosity
     ``A exp(B / T)``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..errors import ConfigError
from ..samples import FrictionSamples
from ..units import DEG

__all__ = [
    "KINDS",
    "REPORTING_SEEDS",
    "TUNING_SEEDS",
    "HeldOutDraw",
    "HeldOutLaw",
    "draw",
    "heldout_law",
]

#: Seeds a developer may tune on (look at, choose defaults with).
TUNING_SEEDS: tuple[int, ...] = tuple(range(100))

#: Seeds the benchmark reports; disjoint from :data:`TUNING_SEEDS`.
REPORTING_SEEDS: tuple[int, ...] = (1001, 1002, 1003)

#: Raw samples averaged into one sample (``count``); ``std`` is then ``noise * sqrt(count)``.
COUNT = 100


def _grid_law(velocity, load, temperature) -> np.ndarray:
    """Kind ``"grid"`` (module notes)."""
    v = np.asarray(velocity, dtype=float)
    av = np.abs(v)
    al = np.abs(np.asarray(load, dtype=float))
    dt = np.asarray(temperature, dtype=float) - 30.0
    coulomb = (0.05 + 0.45 * al) * (1.0 - 0.004 * dt)
    stribeck = (0.06 + 0.25 * al) * np.exp(-((av / (3.0 * DEG)) ** 2))
    viscous = 0.25 * np.exp(-dt / 60.0) * av**0.85
    return np.sign(v) * (coulomb + stribeck + viscous)


def _arrhenius(temperature, beta_ref: float, t_ref: float = 35.0, e_over_r: float = 2500.0):
    t = np.asarray(temperature, dtype=float) + 273.15
    return beta_ref * np.exp(e_over_r * (1.0 / t - 1.0 / (t_ref + 273.15)))


def _asym_law(velocity, load, temperature) -> np.ndarray:
    """Kind ``"asym_arrhenius"`` (module notes); ``load`` is ignored."""
    v = np.asarray(velocity, dtype=float)
    av = np.abs(v)
    pos = 0.11 + 0.09 * np.exp(-((av / 0.04) ** 1.2)) + _arrhenius(temperature, 0.06) * av
    neg = 0.085 + 0.12 * np.exp(-((av / 0.07) ** 1.2)) + _arrhenius(temperature, 0.05) * av
    return np.where(v > 0, pos, np.where(v < 0, -neg, 0.0)) + 0.0 * np.asarray(load, float)


def _sigmoid_law(velocity, load, temperature) -> np.ndarray:
    """Kind ``"sigmoid"`` (module notes, [GZ] eq. 7); ``temperature`` is ignored."""
    v = np.asarray(velocity, dtype=float)
    phi1 = 0.35 + 0.04 * np.abs(np.asarray(load, dtype=float))
    phi2, phi3 = 25.0, 0.03
    f = phi1 / (1.0 + np.exp(-phi2 * (v + phi3))) - phi1 / (1.0 + np.exp(-phi2 * phi3))
    return f + 0.03 * v + 0.0 * np.asarray(temperature, float)


@dataclass(frozen=True)
class HeldOutDraw:
    """One seed's draw of a held-out law: training samples and a held-out set.

    Attributes
    ----------
    train, test : FrictionSamples
        Noisy samples (the design grid; random points in its box).
    train_truth, test_truth : ndarray
        The true friction at their rows [N m].
    noise : float
        Standard deviation of the averaged samples' noise [N m].
    seed : int
    """

    train: FrictionSamples
    test: FrictionSamples
    train_truth: np.ndarray
    test_truth: np.ndarray
    noise: float
    seed: int


@dataclass(frozen=True, eq=False)
class HeldOutLaw:
    """A true friction law with its sampling design and noise (module notes).

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`.
    description : str
        The law in a sentence.
    law : callable
        ``law(velocity, load, temperature) -> friction`` [N m], broadcasting.
    velocities : ndarray
        Positive speed levels [rad/s].
    loads, temperatures : ndarray or None
        Levels [N m], [degC]; None when the kind does not measure the input (the samples'
        column is then not measured).
    combined : bool
        Combined samples (direction 0, ``v > 0``) rather than both directions apart.
    noise : float
        Standard deviation of the averaged samples [N m].
    n_test : int
        Points of the held-out set.
    """

    kind: str
    description: str
    law: Callable[..., np.ndarray]
    velocities: np.ndarray
    loads: np.ndarray | None
    temperatures: np.ndarray | None
    combined: bool
    noise: float
    n_test: int

    def grid(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(velocity, load, temperature, direction) of the training design."""
        loads = self.loads if self.loads is not None else np.array([np.nan])
        temps = self.temperatures if self.temperatures is not None else np.array([np.nan])
        signs = np.array([1.0]) if self.combined else np.array([-1.0, 1.0])
        s, t, v, lo = np.meshgrid(signs, temps, self.velocities, loads, indexing="ij")
        direction = np.zeros(s.size) if self.combined else s.ravel()
        return (s * v).ravel(), lo.ravel(), t.ravel(), direction

    def _box(self, rng: np.random.Generator, n: int):
        lo_v, hi_v = np.log(self.velocities.min()), np.log(self.velocities.max())
        v = np.exp(rng.uniform(lo_v, hi_v, n))
        if not self.combined:
            v = v * rng.choice([-1.0, 1.0], n)
        load = (
            rng.uniform(self.loads.min(), self.loads.max(), n)
            if self.loads is not None
            else np.full(n, np.nan)
        )
        temp = (
            rng.uniform(self.temperatures.min(), self.temperatures.max(), n)
            if self.temperatures is not None
            else np.full(n, np.nan)
        )
        direction = np.zeros(n) if self.combined else np.sign(v)
        return v, load, temp, direction

    def truth(self, velocity, load, temperature) -> np.ndarray:
        """The true friction; for combined samples, half the difference of the two
        directions (eq. 11 of the BAS-RBFNN paper) at ``v > 0``."""
        load = np.nan_to_num(np.asarray(load, dtype=float))
        temperature = np.where(np.isnan(temperature), 25.0, temperature)
        if self.combined:
            return 0.5 * (
                self.law(velocity, load, temperature)
                - self.law(-np.asarray(velocity), load, temperature)
            )
        return self.law(velocity, load, temperature)

    def _samples(self, v, load, temp, direction, rng, what: str, seed: int):
        truth = self.truth(v, load, temp)
        y = truth + rng.normal(0.0, self.noise, truth.shape)
        n = truth.size
        samples = FrictionSamples(
            velocity=v,
            load=None if self.loads is None else load,
            temperature=None if self.temperatures is None else temp,
            friction=y,
            direction=direction,
            count=np.full(n, COUNT),
            std=np.full(n, self.noise * np.sqrt(COUNT)),
            source=f"held-out law {self.kind}, {what}, seed {seed}",
        )
        return samples, truth

    def draw(self, seed: int) -> HeldOutDraw:
        """Training samples (the grid plus noise) and a held-out set (``n_test`` random points
        in the grid's box, log-uniform in speed, plus independent noise) for ``seed``."""
        rng = np.random.default_rng([int(seed), KINDS.index(self.kind)])
        train, train_truth = self._samples(*self.grid(), rng, "training grid", seed)
        test, test_truth = self._samples(*self._box(rng, self.n_test), rng, "held-out", seed)
        return HeldOutDraw(train, test, train_truth, test_truth, self.noise, int(seed))


def _make(kind: str) -> HeldOutLaw:
    if kind == "grid":
        return HeldOutLaw(
            kind,
            "Bittencourt-style: Coulomb (0.05 + 0.45|L|)(1 - 0.004 (T - 30)), Stribeck excess "
            "(0.06 + 0.25|L|) exp(-(|v| / 3 deg/s)^2), viscous 0.25 exp(-(T - 30)/60) |v|^0.85",
            _grid_law,
            np.geomspace(0.15, 45.0, 12) * DEG,
            np.linspace(0.12, 0.26, 11),
            np.arange(10.0, 50.0, 3.0),
            True,
            0.6e-3,
            600,
        )
    if kind == "asym_arrhenius":
        return HeldOutLaw(
            kind,
            "asymmetric Stribeck (0.11 + 0.09 exp(-(|v|/0.04)^1.2) for v > 0, 0.085 + 0.12 "
            "exp(-(|v|/0.07)^1.2) for v < 0) plus Arrhenius viscous beta(T) |v|, E/R = 2500 K",
            _asym_law,
            np.geomspace(0.005, 3.0, 15),
            None,
            np.array([15.0, 25.0, 35.0, 45.0, 55.0]),
            False,
            2.0e-3,
            300,
        )
    if kind == "sigmoid":
        return HeldOutLaw(
            kind,
            "Franka-like sigmoid (Gaz et al. 2019) with phi1 = 0.35 + 0.04|L|, phi2 = 25 s/rad, "
            "phi3 = 0.03 rad/s, plus 0.03 v",
            _sigmoid_law,
            np.geomspace(0.01, 2.0, 18),
            np.linspace(-3.0, 3.0, 15),
            None,
            False,
            1.5e-3,
            400,
        )
    raise ConfigError(f"unknown held-out law kind {kind!r}; choose one of: {', '.join(KINDS)}")


#: The three kinds, in the order of issue 15's table.
KINDS: tuple[str, ...] = ("grid", "asym_arrhenius", "sigmoid")


def heldout_law(kind: str) -> HeldOutLaw:
    """The held-out law of ``kind`` (one of :data:`KINDS`; module notes)."""
    return _make(str(kind).strip().lower())


def draw(kind: str, seed: int) -> HeldOutDraw:
    """``heldout_law(kind).draw(seed)``."""
    return heldout_law(kind).draw(seed)
