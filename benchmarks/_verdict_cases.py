"""Cases for the verdict-calibration benchmark (``bench_verdicts.py``): friction laws, speed
designs and noise written here, independently of ``fricid.sim`` and ``fricid.models``.

Every case is a noiseless truth ``F(v, load, T)`` (a :class:`Law`), a measured design (the
operating points, per direction, with or without repeated runs), and a noise process (its
true standard deviation ``sigma(x)`` at every input, and how much of it the samples carry).
From these, :func:`make_case` draws the samples; :func:`truth_grid` lays a dense grid over
the measured operating range, where the benchmark compares a fitted model with the truth.

Nothing here imports fricid's laws or simulator: the laws are deliberately outside fricid's
families (a Lorentzian Stribeck dip under a tanh sign, exponentials of powers with other
exponents and a power-law viscous term, piecewise-linear curves in log speed, a different law
per direction, an Arrhenius term in the Coulomb and viscous parts with a multiplicative load
term, and the soft onset of a Dahl-like law at steady state), so the verdict is tested on data
fricid did not generate. Only the data type, :class:`fricid.samples.FrictionSamples`, is
fricid's.

Case classes (one factor set, the rest drawn from the defaults, :data:`CLASSES`):

``regular``     12-20 log-spaced levels, known noise, no repeats
``close``       30-40 levels 3-5 % apart
``irregular``   12-20 levels at random log speeds
``few``         5-6 levels
``gaps``        log-spaced with a missing band (a decade or so)
``lopsided``    one direction with more levels over a wider range than the other
``tiny``        about 12 points in all
``repeats``     3 repeated runs at every level (speeds jittered by 0.5 %)
``hetero``      noise proportional to the friction
``outliers``    two samples with a gross error (10-20 sigma)
``unknown``     no std or count in the samples (the scatter must come from the data)
``gravity``     a position-dependent gravity offset left in each sample (3 runs)
``loadtemp``    a law with load and temperature, measured at several of each
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from fricid.samples import FrictionSamples

__all__ = ["CLASSES", "LAWS", "Case", "Law", "make_case", "truth_grid"]

#: Kelvin offset.
_K = 273.15


@dataclass(frozen=True)
class Law:
    """A noiseless friction law ``F(v, load, T) = sign(v) g_side(|v|, load, T)``.

    Attributes
    ----------
    name : str
        The law's family (:data:`LAWS`).
    g_pos, g_neg : callable
        Magnitude per direction, ``g(speed, load, temperature) -> (n,)`` [N m].
    uses_load_temp : bool
        The law depends on load and temperature (the samples then measure both).
    """

    name: str
    g_pos: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]
    g_neg: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]
    uses_load_temp: bool = False

    def __call__(self, v: np.ndarray, load: np.ndarray, temp: np.ndarray) -> np.ndarray:
        s = np.abs(v)
        g = np.where(v >= 0, self.g_pos(s, load, temp), self.g_neg(s, load, temp))
        return np.sign(v) * g


def _lorentz(rng: np.random.Generator) -> Callable:
    """Coulomb plus a Lorentzian (not exponential) Stribeck dip plus viscous."""
    fc, rise = rng.uniform(0.5, 3.0), rng.uniform(0.2, 1.0)
    vs, b = 10 ** rng.uniform(-2, -0.7), rng.uniform(0.2, 2.0)
    return lambda s, lo, t: fc + fc * rise / (1 + (s / vs) ** 2) + b * s


def _exp_power(rng: np.random.Generator) -> Callable:
    """Stribeck with a stretched or compressed exponential and a power-law viscous term."""
    fc, rise = rng.uniform(0.5, 3.0), rng.uniform(0.2, 1.0)
    vs, a = 10 ** rng.uniform(-2, -0.7), rng.choice([0.5, 3.0])
    b, c = rng.uniform(0.3, 2.0), rng.choice([0.5, 0.7, 1.4])
    return lambda s, lo, t: fc + fc * rise * np.exp(-((s / vs) ** a)) + b * s**c


def _piecewise(rng: np.random.Generator) -> Callable:
    """Piecewise linear in log10 speed through 5 random knots (a kinked curve)."""
    knots = np.linspace(-3.0, 1.0, 5)
    base = rng.uniform(0.5, 3.0)
    values = base * np.cumsum(np.r_[1.0, rng.uniform(-0.25, 0.6, 4)])
    values = np.maximum(values, 0.2 * base)
    return lambda s, lo, t: np.interp(np.log10(np.maximum(s, 1e-6)), knots, values)


def _dahl_steady(rng: np.random.Generator) -> Callable:
    """The soft onset of a Dahl-like law at steady state, ``Fc (1 - exp(-|v|/v0))^(1/i)``,
    plus viscous: no Stribeck dip, a rise from zero instead."""
    fc, v0 = rng.uniform(0.5, 3.0), 10 ** rng.uniform(-2.5, -1.3)
    i, b = rng.choice([1.0, 2.0]), rng.uniform(0.2, 1.5)
    return lambda s, lo, t: fc * (1 - np.exp(-s / v0)) ** (1 / i) + b * s


def _arrhenius(rng: np.random.Generator) -> tuple[Callable, Callable]:
    """Coulomb and viscous parts with Arrhenius factors of different energies, a Stribeck
    dip, and a multiplicative load term; the two directions differ by 20 %."""
    fc, rise, vs = rng.uniform(0.5, 2.0), rng.uniform(0.2, 0.8), 10 ** rng.uniform(-2, -1)
    b, k_load = rng.uniform(0.3, 1.5), rng.uniform(0.01, 0.05)
    e_c, e_v = rng.uniform(200, 800), rng.uniform(1000, 2500)  # E/R [K]

    def law(scale: float) -> Callable:
        def g(s, lo, t):
            arr_c = np.exp(e_c * (1 / (t + _K) - 1 / (25 + _K)))
            arr_v = np.exp(e_v * (1 / (t + _K) - 1 / (25 + _K)))
            dip = fc * rise * np.exp(-np.sqrt(s / vs))
            return scale * ((fc * arr_c + dip) * (1 + k_load * np.abs(lo)) + b * arr_v * s)

        return g

    return law(1.0), law(rng.uniform(0.8, 1.2))


_SYM: dict[str, Callable] = {
    "lorentz": _lorentz,
    "exp_power": _exp_power,
    "piecewise": _piecewise,
    "dahl_steady": _dahl_steady,
}

#: The law families.
LAWS: tuple[str, ...] = (*_SYM, "asym_mixed", "arrhenius_load")


def make_law(name: str, rng: np.random.Generator) -> Law:
    """A law of family ``name`` with parameters drawn from ``rng``."""
    if name in _SYM:
        g = _SYM[name](rng)
        return Law(name, g, g)
    if name == "asym_mixed":  # a different family per direction
        a, b = rng.choice(list(_SYM), size=2, replace=False)
        return Law(f"asym_mixed({a}/{b})", _SYM[a](rng), _SYM[b](rng))
    if name == "arrhenius_load":
        gp, gn = _arrhenius(rng)
        return Law(name, gp, gn, uses_load_temp=True)
    raise ValueError(f"unknown law {name!r}")


# -- speed designs: positive speeds per direction ------------------------------------------


def _levels(design: str, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """The speed levels [rad/s] of the positive and the negative direction."""
    lo, hi = 10 ** rng.uniform(-2.3, -1.3), 10 ** rng.uniform(0.0, 0.7)
    if design == "regular":
        s = np.geomspace(lo, hi, rng.integers(12, 21))
        return s, s
    if design == "close":
        n = int(rng.integers(30, 41))
        s = lo * np.cumprod(np.r_[1.0, 1 + rng.uniform(0.03, 0.05, n - 1)])
        return s, s
    if design == "irregular":
        n = int(rng.integers(12, 21))
        s = np.sort(10 ** rng.uniform(np.log10(lo), np.log10(hi), n))
        return s, s
    if design == "few":
        s = np.geomspace(lo, hi, rng.integers(5, 7))
        return s, s
    if design == "gaps":
        s = np.geomspace(lo, hi, 18)
        mid = rng.uniform(0.3, 0.6) * np.log10(hi / lo) + np.log10(lo)
        keep = np.abs(np.log10(s) - mid) > 0.45
        return s[keep], s[keep]
    if design == "lopsided":
        return np.geomspace(lo, hi, 16), np.geomspace(lo * 3, hi / 2, 6)
    if design == "tiny":
        s = np.geomspace(lo, hi, 6)
        return s, s
    raise ValueError(f"unknown design {design!r}")


#: Defaults of every case; a class overrides one or two.
_DEFAULTS: dict[str, Any] = {
    "design": "regular",
    "repeats": 1,
    "noise": "homo",
    "given": True,
    "gravity": False,
}

#: Case class -> what it sets (module notes).
CLASSES: dict[str, dict[str, Any]] = {
    "regular": {},
    "close": {"design": "close"},
    "irregular": {"design": "irregular"},
    "few": {"design": "few"},
    "gaps": {"design": "gaps"},
    "lopsided": {"design": "lopsided"},
    "tiny": {"design": "tiny"},
    "repeats": {"repeats": 3, "given": False},
    "hetero": {"noise": "hetero"},
    "outliers": {"noise": "outliers"},
    "unknown": {"given": False, "design": "irregular"},
    "gravity": {"gravity": True, "repeats": 3},
    "loadtemp": {"law": "arrhenius_load"},
}

#: Raw points averaged into one sample when the noise is "given" (std and count carried).
_COUNT = 50


@dataclass
class Case:
    """One benchmark case: its truth, design, noise and drawn samples.

    Attributes
    ----------
    id : int
        Case number (also the seed of its draws).
    klass : str
        Case class (:data:`CLASSES`).
    law : Law
        The noiseless truth.
    samples : FrictionSamples
        What fricid is given.
    sigma : callable
        The true noise std [N m] of a sample at inputs ``(v, load, T)``.
    spec : dict
        The factors (design, repeats, noise, given, gravity, levels per direction, ...);
        ``gravity_amp`` [N m] is the amplitude ``a`` of the gravity offset ``a sin(phi)``,
        ``phi`` uniform in (-pi/2, pi/2), that every sample of a gravity case carries (0
        otherwise): a new measured sample of the same process carries one too.
    ranges : dict
        The measured operating range: ``pos`` and ``neg`` speed ``(min, max)`` (absent for
        a direction not measured), ``load`` and ``temperature`` ``(min, max)`` or None.
    """

    id: int
    klass: str
    law: Law
    samples: FrictionSamples
    sigma: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]
    spec: dict[str, Any] = field(default_factory=dict)
    ranges: dict[str, Any] = field(default_factory=dict)


def _points(
    law: Law, pos: np.ndarray, neg: np.ndarray, repeats: int, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Velocity, load and temperature of every sample (repeats jittered by 0.5 %)."""
    v = np.r_[pos, -neg]
    v = np.repeat(v, repeats)
    if repeats > 1:
        v = v * (1 + rng.uniform(-0.005, 0.005, v.size))
    if not law.uses_load_temp:
        return v, np.zeros_like(v), np.full_like(v, 25.0)
    loads, temps = np.array([0.0, 10.0, 20.0]), np.array([15.0, 35.0, 55.0])
    combos = [(a, b) for a in loads for b in temps]
    pick = rng.choice(len(combos), size=(v.size, 2))
    v = np.repeat(v, 2)
    lo = np.array([combos[k][0] for k in pick.ravel()]) * np.sign(rng.uniform(-1, 1, v.size))
    t = np.array([combos[k][1] for k in pick.ravel()])
    return v, lo, t


def make_case(case_id: int, klass: str, seed: int) -> Case:
    """Draw case ``case_id`` of class ``klass`` from ``seed`` (module notes)."""
    rng = np.random.default_rng(seed)
    spec = {**_DEFAULTS, **CLASSES[klass]}
    law_name = spec.get("law") or rng.choice([n for n in LAWS if n != "arrhenius_load"])
    law = make_law(str(law_name), rng)
    pos, neg = _levels(spec["design"], rng)
    v, lo, t = _points(law, pos, neg, spec["repeats"], rng)
    truth = law(v, lo, t)
    level = float(np.sqrt(np.mean(truth**2)))
    frac = rng.uniform(0.01, 0.03)
    if spec["noise"] == "hetero":
        k = rng.uniform(0.02, 0.05)

        def sigma(vv, ll, tt):
            return k * np.abs(law(vv, ll, tt))
    else:
        s0 = frac * level

        def sigma(vv, ll, tt):
            return np.full(np.shape(vv), s0)

    sd = sigma(v, lo, t)
    y = truth + sd * rng.standard_normal(v.size)
    if spec["noise"] == "outliers":
        bad = rng.choice(v.size, size=2, replace=False)
        y[bad] += np.sign(y[bad]) * rng.uniform(10, 20, 2) * sd[bad]
    amp = 0.0
    if spec["gravity"]:  # eq. 7's gravity at each run's mean position, left in
        amp = rng.uniform(0.1, 0.4) * level
        y = y + amp * np.sin(rng.uniform(-np.pi / 2, np.pi / 2, v.size))
    kw: dict[str, Any] = {}
    if spec["given"]:
        kw = {"count": np.full(v.size, _COUNT), "std": sd * np.sqrt(_COUNT)}
    samples = FrictionSamples(
        velocity=v,
        load=lo if law.uses_load_temp else None,
        temperature=t if law.uses_load_temp else None,
        friction=y,
        direction=np.sign(v),
        source=f"case{case_id}",
        **kw,
    )
    spec = {
        **spec,
        "law": law.name,
        "levels_pos": int(pos.size),
        "levels_neg": int(neg.size),
        "gravity_amp": float(amp),
    }
    ranges: dict[str, Any] = {
        "pos": (float(pos.min()), float(pos.max())),
        "neg": (float(neg.min()), float(neg.max())),
        "load": (float(lo.min()), float(lo.max())) if law.uses_load_temp else None,
        "temperature": (float(t.min()), float(t.max())) if law.uses_load_temp else None,
    }
    return Case(case_id, klass, law, samples, sigma, spec, ranges)


def truth_grid(case: Case, n: int = 200, seed: int = 12345) -> np.ndarray:
    """A dense grid ``(m, 3)`` over the measured operating range: ``n`` log-uniform speeds
    from the slowest to the fastest measured speed of each direction (a gap inside the
    range included), and, for a law with load and temperature, load and temperature drawn
    uniformly in their measured ranges (seeded: the same grid for every model)."""
    rng = np.random.default_rng(seed)
    vs = [sign * np.geomspace(*case.ranges[side], n) for side, sign in (("pos", 1), ("neg", -1))]
    v = np.concatenate(vs)
    if case.ranges["load"] is None:
        return np.column_stack([v, np.zeros_like(v), np.full_like(v, 25.0)])
    lo = rng.uniform(*case.ranges["load"], v.size)
    t = rng.uniform(*case.ranges["temperature"], v.size)
    return np.column_stack([v, lo, t])
