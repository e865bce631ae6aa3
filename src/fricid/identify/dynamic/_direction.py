"""Whether the friction differs by direction beyond a symmetric law fitted to a trajectory
(``coulomb_viscous``, ``stribeck``, ``lugre``, ``dahl``), or whether the log can tell.

The friction's difference by direction, half of it, is a constant torque; a symmetric law
fitted with the gravity lets ``p_x cos q - p_y sin q`` take it up, exactly where the motion
covers little of the joint's range (``cos q`` then hardly changes). The test is the
``coulomb_viscous_asym`` regression on the symmetric fit's own samples (beyond a Stribeck
law's rise), corrected for the derivative window as the fit is (:func:`per_direction`), and
:func:`direction_caveat` reads it: a caveat where the levels differ, or may, a note on the
gravity where the log cannot tell.

Measured (``benchmarks/bench_direction.py --seeds 4 --first-seed 10``, the independent LuGre
simulator's logs, three joints, PD-tracked chirps and trapezoids and open-loop torque steps;
the thresholds set on seeds 3-4; ``benchmarks/results/direction.txt``): with the friction 10 %
or 20 % weaker backwards, a ``lugre`` fit's gravity intervals missed the truth in 68 of 72
logs, none of which said anything before; now 3 say nothing (2 of them missed). Of 36
symmetric logs, 4 got a caveat (1 'differs', 3 'may differ'), 15 nothing.
"""

from __future__ import annotations

import math

import numpy as np

from ...models import get_model
from ._data import DerivativeFilter, Series
from ._routes import _regression
from ._window import corrected, predicted_bias

__all__ = ["DIRECTION_P", "MIN_CLUSTERS", "direction_caveat", "per_direction"]

#: Largest p-value of the test that a per-direction law fits better, below which a symmetric
#: law's fit says so (:func:`direction_caveat`).
DIRECTION_P = 1e-3

#: The fewest clusters of the cluster-robust covariance (a log of 5 s in blocks of 0.5 s)
#: for the test to say the friction differs; with fewer it says it may (:func:`direction_caveat`).
#: Why. With few clusters the covariance is too rough for a test at :data:`DIRECTION_P`: the
#: chi-square over-rejects, and four clusters (a 2 s log) called four of five symmetric
#: virtual joints' friction different by direction at p down to 9e-9 (``fricid simulate
#: --trajectory multisine --duration 2``, seeds 0-4). Tried and not kept
#: (``benchmarks/bench_direction.py --seeds 4 --first-seed 10``, results not kept): the
#: small-sample F(2, G - 2) form weakened the test on the 10 s logs it was set on (at F's
#: equivalent of the chi-square's 1e-3 at 20 clusters, Dahl's silent gravity misses at 10 %
#: weaker backwards rose from 1 to 3 of 36), and no claim at all below 10 clusters left
#: Stribeck fits of asymmetric 10 s logs with 3 to 9 clusters silent (misses 1 -> 3 of 36 at
#: 20 % weaker backwards); a 'may differ' keeps their caveat.
MIN_CLUSTERS = 10


#: What a symmetric law's caveat advises, per law fitted.
_DIRECTION_ADVICE = {
    "coulomb_viscous": "fit coulomb_viscous_asym",
    "stribeck": "fit stribeck_asym",
    "lugre": (
        "this LuGre has one Coulomb and break-away level for both directions, so its tau_c "
        "is about their mean, p_x, p_y are off by about half the difference, and sigma_0, "
        "sigma_1 take up the misfit at each reversal (their intervals may not hold); fit "
        "lugre_asym (the levels per direction; a torque sensor's offset looks the same)"
    ),
    "dahl": (
        "fricid's Dahl has one Coulomb level for both directions, so its tau_c is about their "
        "mean and p_x, p_y are off by about half the difference; coulomb_viscous_asym fits "
        "the steady state per direction"
    ),
}


#: A gravity coefficient whose standard error with a level per direction is this many times
#: its symmetric fit's rests on the friction being the same both ways
#: (:func:`direction_caveat`).
GRAVITY_BY_SYMMETRY = 3.0
#: ... and when the log leaves the Coulomb levels' difference open by more than this share of
#: their mean (the 95 % half-width): real joints differ by direction by some per cent to tens
#: of per cent; a log that bounds the difference well below that leaves the gravity little to
#: take up.
DIRECTION_OPEN = 0.05


def direction_caveat(asym, law: str = "coulomb_viscous", symmetric=None) -> tuple[str, str]:
    """``(caveat, note)`` on the friction's difference by direction beyond the symmetric law
    ``law``: a caveat where it differs or may, a note on the gravity where the log cannot
    tell; '' for none.

    Differs: the Wald test, with the cluster-robust covariance, that ``asym`` (the
    ``coulomb_viscous_asym`` regression on the same samples, :func:`per_direction`)
    has equal Coulomb levels and viscous coefficients both ways, at p <=
    :data:`DIRECTION_P`. Fitted with a symmetric law, a per-direction one's difference is
    taken up by the gravity and the levels (a new user's log: p_x -1.2464 [-1.2492, -1.2436]
    for -1.2, no caveat).

    Cannot tell: half the difference of the levels is a constant torque, which a motion over
    a small part of the joint's range cannot tell from the gravity (``cos q`` hardly
    changes); a symmetric law's fit then determines the gravity only because it takes the
    friction to be the same both ways. Where a gravity coefficient's standard error in
    ``asym`` is :data:`GRAVITY_BY_SYMMETRY` times its own in ``symmetric`` (the symmetric
    regression on the same samples) and the log leaves the levels' difference open by
    :data:`DIRECTION_OPEN` of their mean, the note says so; a caveat, where the difference
    is two of its standard errors from zero. A LuGre joint 30 % weaker backwards
    (``benchmarks/_lugre_truth.py``, geared, PD-tracked chirp of 0.3 rad, seed 3) got tau_c
    1.019 [1.016, 1.023] for 1.2 / 0.84 and p_x -0.776 [-0.778, -0.774] for -0.591, and no
    caveat; with a level per direction p_x was -0.592 +/- 0.086, 78 times the symmetric
    fit's standard error, and the levels' difference 0.359 +/- 0.17 N m."""
    i = [asym.names.index(n) for n in ("f_c_pos", "beta_pos", "f_c_neg", "beta_neg")]
    A = np.array([[1.0, 0.0, -1.0, 0.0], [0.0, 1.0, 0.0, -1.0]])
    d = A @ asym.values[i]
    C = A @ asym.cov[np.ix_(i, i)] @ A.T
    if not np.all(np.isfinite(C)) or np.linalg.det(C) <= 0:
        return "", ""
    from scipy.stats import chi2

    p = float(chi2.sf(float(d @ np.linalg.solve(C, d)), 2))
    clusters = int(getattr(asym, "clusters", 0) or 0)
    c_pos, v_pos, c_neg, v_neg = (float(asym.values[j]) for j in i)
    se_c, se_v = (math.sqrt(C[k, k]) for k in (0, 1))
    advice = _DIRECTION_ADVICE.get(law, _DIRECTION_ADVICE["coulomb_viscous"])
    note = _gravity_by_symmetry(asym, symmetric, d[0], se_c, c_pos + c_neg, splits_levels(asym))
    if p <= DIRECTION_P and 0 < clusters < MIN_CLUSTERS:  # too few to settle it: 'may'
        return (
            f"the friction may differ by direction (p = {p:.2g} from only {clusters} "
            "independent stretches of the log, too few to settle it; per direction: Coulomb "
            f"{c_pos:.4g} / {c_neg:.4g} N m, their difference {d[0]:.3g} +/- {se_c:.2g}): a "
            f"longer log tells; {advice}"
        ), note
    if p <= DIRECTION_P:
        return (
            f"the friction differs by direction (p {'< 1e-12' if p < 1e-12 else f'= {p:.2g}'}; "
            f"per direction: Coulomb {c_pos:.4g} / {c_neg:.4g} N m, their difference "
            f"{d[0]:.3g} +/- {se_c:.2g}; viscous {v_pos:.4g} / {v_neg:.4g} N m s/rad, their "
            f"difference {d[1]:.3g} +/- {se_v:.2g}; +/- one standard error): this symmetric "
            f"law's levels and gravity take up the difference; {advice}"
        ), note
    if note and abs(d[0]) > 2.0 * se_c:
        return f"the friction may differ by direction: {note}; {advice}", ""
    return "", note


def _gravity_by_symmetry(
    asym, symmetric, diff: float, diff_se: float, levels: float, split: bool
) -> str:
    """The 'cannot tell' part of :func:`direction_caveat` (``levels``: the Coulomb levels'
    sum; ``split``: whether ``asym`` determines them, :func:`splits_levels`; where it does
    not, their mean is no yardstick and the note says why instead: the cdw95 trapezoid of
    :func:`start_levels` read "+/- 5.2 N m against their mean 3.4e-13 N m")."""
    open_share = 1.96 * diff_se / max(0.5 * abs(levels), 1e-300)
    if symmetric is None or not open_share > DIRECTION_OPEN:
        return ""
    parts = []
    for name in ("p_x", "p_y"):
        if name not in asym.names or name not in symmetric.names:
            continue
        wide = float(asym.stderr[asym.names.index(name)])
        own = float(symmetric.stderr[symmetric.names.index(name)])
        if own > 0 and wide > GRAVITY_BY_SYMMETRY * own:
            value = float(asym.values[asym.names.index(name)])
            parts.append(
                f"{name} {value:.4g} +/- {wide:.2g} with a level per direction, +/- "
                f"{own:.2g} with one"
            )
    if not parts:
        return ""
    mean = 0.5 * abs(levels)
    if not split:
        share = (
            f"+/- {1.96 * diff_se:.2g} N m, the levels themselves not determined: the samples "
            "slide at too few speeds to tell a Coulomb level from a viscous term"
        )
    elif open_share <= 10.0:
        share = f"+/- {100 * open_share:.0f} % of their mean"
    else:  # a share of 1e17 % says nothing: levels near zero are given as they are
        share = f"+/- {1.96 * diff_se:.2g} N m against their mean {mean:.2g} N m"
    return (
        "the log does not tell the gravity from a difference of the friction by direction "
        f"(the Coulomb levels' difference is {_to_its_error(diff, diff_se):.3g} N m with a "
        "standard error of "
        f"{diff_se:.2g}, its 95 % interval {share}; half of "
        "a difference is a constant torque the gravity takes up): the gravity rests on the "
        "friction being the same both ways (the regression on the same samples gives "
        f"{'; '.join(parts)}); a motion over more of the joint's range tells them apart"
    )


def _to_its_error(value: float, stderr: float) -> float:
    """``value`` rounded to two significant digits of its standard error (a difference of
    6.9e-13 N m with a standard error of 2.7 is 0)."""
    if not (math.isfinite(value) and math.isfinite(stderr) and stderr > 0):
        return value
    return round(value, 1 - math.floor(math.log10(stderr))) + 0.0


#: Where a Stribeck law's rise is below this share of its height, the per-direction test
#: (:func:`per_direction`) takes the samples as Coulomb-viscous.
RISE_LEFT = 0.01
#: The fewest samples beyond the rise for the test to keep to them; with fewer it takes every
#: sliding sample.
MIN_BEYOND_RISE = 200


def per_direction(series: Series, filt: DerivativeFilter, vf, acc, mask, args: tuple, stage):
    """The ``coulomb_viscous_asym`` regression that tests a symmetric fit ``stage`` (its
    samples ``mask``, window and ``args``: :func:`._routes._regression`'s; the friction is
    searched even where the symmetric fit took it fixed from sweeps), corrected as the fit is
    (:func:`corrected`): for :func:`direction_caveat`.

    For a Stribeck law, on the samples beyond its rise (below :data:`RISE_LEFT` of its height
    at the fit's ``w_s`` and ``delta``) where there are :data:`MIN_BEYOND_RISE` of them: a
    per-direction Stribeck law's levels are ill-determined where the rise is narrow or not
    seen (a Stribeck velocity of 1 mrad/s, ``benchmarks/_lugre_truth.py``'s cdw95 joint: the
    difference of the levels came out -0.9 +/- 24 N m for levels of 1 N m). Uncorrected, the
    noise of a 1024-count encoder at 100 Hz had put a symmetric truth's levels (0.3 N m) at
    0.19 and 0.36 both ways, a difference of p = 1e-8."""
    if args[0].name == "stribeck":
        v = dict(zip(stage.names, stage.values, strict=False))
        if "w_s" not in v:  # the static part fixed from sweeps
            v = dict(zip(args[0].param_names, args[-1], strict=True))
        beyond = v["w_s"] * np.log(1.0 / RISE_LEFT) ** (1.0 / max(v["delta"], 1e-3))
        fast = mask & (np.abs(vf) >= beyond)
        mask = fast if fast.sum() >= MIN_BEYOND_RISE else mask
    return _levels(series, filt, vf, acc, mask, args)


def _levels(series: Series, filt: DerivativeFilter, vf, acc, mask, args: tuple):
    """The ``coulomb_viscous_asym`` regression on the samples ``mask``, corrected."""
    model = get_model("coulomb_viscous_asym")
    stage = _regression(series, vf, acc, mask, model, *args[1:-1], None)[0]
    return corrected(stage, predicted_bias(series, filt, stage, mask, model))


def start_levels(series: Series, filt: DerivativeFilter, vf, acc, mask, args: tuple, asym):
    """The per-direction Coulomb levels and viscous coefficients a LuGre search's falling start
    takes (:func:`._filtered.falling_start`): :func:`per_direction`'s ``asym`` where it splits
    them (every Coulomb level's 95 % interval above 0), else the same regression on every
    sliding sample ``mask``.

    Why. Beyond the rise a trapezoid slides at its plateaus' speeds only, where a Coulomb level
    and a viscous term are one number: on ``benchmarks/_lugre_truth.py``'s cdw95 trapezoid
    (1 kHz, 2^20 counts/rev, seed 0; tau_c 1, sigma_2 0.4) the split came out tau_c 3e-13,
    sigma_2 1.39, and the search from there ended at 9 times the filtered residual of the
    rising valley it was to test (0.44 against 0.052 N m). Every sliding sample, the ramps'
    too, gives 1.12 and 0.28, from where the search finds tau_c 0.998 and sigma_2 0.402
    (0.018 N m)."""
    if splits_levels(asym):
        return asym
    return _levels(series, filt, vf, acc, mask, args)


def splits_levels(asym) -> bool:
    """Whether the ``coulomb_viscous_asym`` regression ``asym`` determines both Coulomb
    levels (each 95 % interval above 0) rather than trading them for the viscous terms."""
    rows = asym.table()
    return all(rows[f"f_c_{d}"]["ci95_low"] > 0 for d in ("pos", "neg"))
