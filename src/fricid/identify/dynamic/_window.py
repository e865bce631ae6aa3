"""The derivative window from the encoder, for the regression of the static models.

The regression ``u = J qdd + f(qd; theta) - (p_x cos q - p_y sin q)`` (:mod:`._routes`) takes
``qdd`` from a Savitzky-Golay second derivative of the quantised position
(:class:`._data.DerivativeFilter`). The encoder's steps are noise in that regressor, and noise
in a regressor biases least squares (errors in variables; Fuller 1987, ch. 1.1): with ``X``
the regression's columns and ``e`` the acceleration's error, ``theta_hat = theta - J X^+ e``.
J falls by the noise's share of the acceleration's variance; every other parameter moves
with it, and by the noise's own correlation with its column (the encoder's error is a
function of the position). A wider window cuts the noise (as ``W^-5`` for white noise) but
bends the motion: the cubic's second derivative falls short of ``(2 pi f)^2`` by a gain
``g(f)`` at the motion's frequencies, which raises J. :func:`predicted_bias` estimates both
parts of ``e`` from the log: the noise as what the filter gives beyond its output on the
position smoothed over three windows (:func:`_noise`), the bending from the filtered
acceleration's spectrum and the filter's gain (:func:`_distortion`).

The default window, 21 ms, suits a fine encoder. Through 4096 counts per revolution at 1 kHz
a 0.25-0.75 Hz multi-sine gave J = 0.00108 [0.00084, 0.0013] for a truth of 0.01, with f_c,
beta and p_y outside their intervals too (a new user's trial log, open loop, 20 s); J's error
and its prediction against the window on that log (the white-noise formula ``Delta^2 / 12
sum h^2`` had put the noise's share at twice what it was: the quantisation error of a joint
moving less than a count per sample is not white):

====== ========== ===========
window J's error  predicted
====== ========== ===========
21 ms  -89 %      -92 %
41 ms  -18 %      -19 %
51 ms  -5.4 %     -6.1 %
100 ms +1.0 %     +0.3 %
====== ========== ===========

(J's error includes +0.5 % of the torque noise's, the error at every window with the exact
position.) On the generator of ``benchmarks/bench_window.py`` (seeds 0-11, 4096 counts, an
85 ms window) every parameter's error, in standard errors, less its prediction had an RMS of
0.46-0.80, where the errors themselves reached 4.7 (p_y, whose lean of -1.6 on average the
prediction put at -1.6).

So: :func:`choose_window` widens the window by :data:`LADDER` steps while the noise outweighs
the bending and some predicted bias exceeds :data:`BIAS_SHARE` of its standard error (or
narrows it while the bending outweighs the noise: a noise-free log's fast motion), then
bisects to where J's predicted bias changes sign (the regression run again at each window
tried); :func:`corrected` subtracts the predicted biases there and adds
:data:`CORRECTION_ERROR` of each correction to its standard error. A window given by the
caller is kept and corrected the same way. The window, the predicted biases and whether they
were applied go into the provenance (``derivative``'s ``bias``); a correction whose own error
exceeds the parameter's standard error is warned about (:class:`DerivativeBiasWarning`) and
named in the trust verdict's caveats. On the trial log the window is then 80 ms and J =
0.01005 [0.00996, 0.01014]; f_c, beta, p_x and p_y hold the truth too.

Intervals covering the truth, of 20, on logs of that independent generator (``python
benchmarks/bench_window.py``, report seeds 100-119; tuned on seeds 0-19 and the trial log):
before (the 21 ms window, uncorrected: the same run at 6bcddcc), the 21 ms window given and
corrected, and now (``benchmarks/results/window.txt``):

======== ============ ============ ============ ============ ============ ==================
counts   inertia      f_c          beta         p_x          p_y          J's median error
======== ============ ============ ============ ============ ============ ==================
4096     0 / 15 / 20  4 / 20 / 20  7 / 20 / 20  20 / 20 / 20 0 / 15 / 19  84 / 17 / 0.08 %
16384    0 / 19 / 20  4 / 20 / 20  7 / 20 / 20  20 / 20 / 16 0 / 19 / 20  26 / 1.1 / 0.06 %
2^20     20 / 19 / 19 20 / 20 / 20 19 / 20 / 20 16 / 16 / 16 20 / 20 / 20 0.08 / 0.07 / 0.07 %
======== ============ ============ ============ ============ ============ ==================

(p_x's 16 of 20 at 16384 and 2^20 counts is these seeds' luck: over seeds 100-139 its error
over its standard error has an RMS of 1.01-1.05 at 16384, 2^17 and 2^20 counts.) The seconds
of a static trajectory fit grow up to 5 times (a regression per window tried: a tenth of a
second each for ``coulomb_viscous``).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np
from scipy import signal

from ...errors import FricidWarning, user_stacklevel
from ..static.uncertainty import DETERMINED_RCOND
from ._data import DerivativeFilter, Series

__all__ = [
    "BIAS_SHARE",
    "DerivativeBiasWarning",
    "bias_caveat",
    "choose_window",
    "corrected",
    "predicted_bias",
]

#: Largest predicted bias, over the parameter's standard error, at which a window is kept
#: (:func:`choose_window`).
BIAS_SHARE = 0.5
#: Ratio of one window of the ladder to the next; bisections between the two that bracket
#: J's predicted bias changing sign.
LADDER = 1.25
BISECT = 5
#: Longest window of the ladder [s], and its largest share of the log.
MAX_WINDOW = 0.5
MAX_LOG_SHARE = 0.1
#: The reference smoothing of the position for the noise (:func:`_noise`): its window, in
#: windows, and its polynomial order over the filter's.
REFERENCE = 3
REFERENCE_ORDER = 2
#: The share of a correction taken as its own standard error, added in quadrature to the
#: parameter's (:func:`corrected`).
CORRECTION_ERROR = 0.25
#: The noise share is read at most as this (all of the acceleration's variance would put J's
#: bias at infinity).
MAX_SHARE = 0.99
#: Times its periodogram the acceleration's noise is taken out of its spectrum.
NOISE_MARGIN = 5.0
#: A regression at a window: ``(vf, acc, mask, stage, theta, c, residual)``.
Fit = tuple[Any, ...]


class DerivativeBiasWarning(FricidWarning):
    """The encoder's noise in the acceleration, or the derivative filter's bending of the
    motion, biases a trajectory's parameters by a sizeable part of their intervals."""


def _noise(series: Series, filt: DerivativeFilter) -> tuple[np.ndarray, ...]:
    """The filtered acceleration and its noise, the filtered velocity and its noise: each the
    filter's output less its output on the position smoothed over :data:`REFERENCE` windows
    (the encoder's steps and any noise are what that smoothing takes out, white or not; the
    motion it bends is bent far less than the noise share :data:`BIAS_SHARE` is about). On
    the log of the module notes this share matched J's error within a tenth of itself from
    45 % down to 5 %; the white-noise formula ``Delta^2 / 12 sum h^2`` had overstated it
    twofold, as the quantisation error of a joint moving less than a count per sample is not
    white."""
    m, dt = filt.samples(1.0 / series.dt), series.dt
    wide = min(REFERENCE * m, series.position.size - (series.position.size + 1) % 2)
    reference = signal.savgol_filter(series.position, wide | 1, filt.order + REFERENCE_ORDER)
    out = []
    for deriv in (2, 1):
        x = signal.savgol_filter(series.position, m, filt.order, deriv=deriv, delta=dt)
        out += [x, x - signal.savgol_filter(reference, m, filt.order, deriv=deriv, delta=dt)]
    return tuple(out)


def _distortion(series: Series, filt: DerivativeFilter, acc, noise) -> np.ndarray:
    """The filter's bending of the motion in the acceleration, ``acc - qdd``: per frequency
    ``A(f) g / (1 + g)``, ``A`` the filtered acceleration's transform and ``1 + g(f)`` the
    filter's gain on ``(2 pi f)^2``, in the pass band where the motion outweighs
    :data:`NOISE_MARGIN` times the noise's periodogram (elsewhere 0)."""
    dt, m = series.dt, filt.samples(1.0 / series.dt)
    h = signal.savgol_coeffs(m, filt.order, deriv=2, delta=dt, use="dot")
    A = np.fft.rfft(acc - acc.mean())
    f = np.fft.rfftfreq(acc.size, dt)
    taps = np.zeros(acc.size)
    taps[np.arange(m) - m // 2] = h  # centred: the response is real (h is even)
    gain = np.fft.rfft(taps).real / -((2 * np.pi * np.where(f > 0, f, 1.0)) ** 2) - 1.0
    motion = np.abs(A) ** 2 > NOISE_MARGIN * np.abs(np.fft.rfft(noise - noise.mean())) ** 2
    keep = motion & (np.abs(gain) < 0.5) & (f > 0)
    return np.fft.irfft(np.where(keep, A * gain / (1.0 + np.where(keep, gain, 0.0)), 0.0), acc.size)


def predicted_bias(
    series: Series, filt: DerivativeFilter, stage, mask, model=None
) -> dict[str, Any] | None:
    """The regression's predicted biases at ``filt`` (module notes): ``{"window",
    "noise_share", "distortion", "relative": J's, "parameters": {name: bias}, "over_stderr":
    {name: |bias| / stderr}, "noise_over_stderr": the same of the noise's part}``; None
    without a Savitzky-Golay filter or the regression's columns.

    The torque is ``X theta - J e + noise`` with ``X`` the regression's columns (the
    acceleration among them with its error ``e``), so least squares gives ``theta_hat =
    theta - J c`` with ``c = X^+ e``: J falls by the share ``c_J`` (``J = J_hat / (1 -
    c_J)``) and every other parameter moves by ``-J c_k``, through J and through the error's
    own correlation with its column (the encoder's error is a function of the position, and
    near the reversals it correlates with the gravity's columns). ``e`` is the noise
    (:func:`_noise`: its ``c_J`` is the noise share) plus the bending (:func:`_distortion`:
    its ``-c_J`` is the distortion). With the friction ``model`` (its parameters first in
    ``stage``), the velocity's noise enters too: the friction it predicts from the filtered
    velocity less that from the reference one, ``d``, moves the parameters by ``-X^+ d`` (at
    1024 counts and 100 Hz the velocity's noise had biased beta by +14 % and f_c by -5 %,
    beyond their intervals in 2 of 5 logs of a new user's trial)."""
    cols = stage.columns
    if filt.method != "savgol" or cols is None or "inertia" not in stage.names:
        return None
    j = stage.names.index("inertia")
    acc, noise, vel, v_noise = _noise(series, filt)
    bend = _distortion(series, filt, acc, noise)[mask]
    friction = np.zeros(int(mask.sum()))
    if model is not None and stage.names[: model.n_params] == list(model.param_names):
        theta = stage.values[None, : model.n_params]
        vf, temperature = vel[mask], series.temperature[mask]
        X = [np.column_stack([v, 0 * v, temperature]) for v in (vf, vf - v_noise[mask])]
        friction = model.predict(theta, X[0])[0] - model.predict(theta, X[1])[0]
    norms = np.linalg.norm(cols, axis=0)
    norms[norms == 0] = 1.0
    errors = np.column_stack([noise[mask], bend, friction])  # the directions the data see
    c_noise, c_bend, c_friction = (
        np.linalg.lstsq(cols / norms, errors, rcond=DETERMINED_RCOND)[0].T / norms
    )
    seen = np.isfinite(stage.stderr) & (stage.stderr > 0)
    c_noise, c_bend = np.where(seen, c_noise, 0.0), np.where(seen, c_bend, 0.0)
    c_friction = np.where(seen, c_friction, 0.0)
    c = c_noise + c_bend
    inertia = stage.values[j] / (1.0 - min(c[j], MAX_SHARE))
    se = np.where(stage.stderr > 0, stage.stderr, np.inf)
    bias = -inertia * c - c_friction
    return {
        "window": filt.window,
        "noise_share": float(c_noise[j]),
        "distortion": -float(c_bend[j]),
        "relative": float(-c[j]),
        "parameters": dict(zip(stage.names, map(float, bias), strict=True)),
        "over_stderr": dict(zip(stage.names, map(float, np.abs(bias) / se), strict=True)),
        "velocity": dict(zip(stage.names, map(float, -c_friction), strict=True)),
        "noise_over_stderr": float(np.max(np.abs(inertia * c_noise + c_friction) / se)),
    }


def _worst(record: dict[str, Any]) -> float:
    return max(record["over_stderr"].values())


def choose_window(
    series: Series,
    filt: DerivativeFilter,
    fit: Fit,
    regress: Callable[[DerivativeFilter], Fit | None],
    model=None,
) -> tuple[DerivativeFilter, Fit, dict[str, Any] | None]:
    """The regression at the derivative window whose predicted biases cancel (module notes),
    ``fit`` being the regression at ``filt`` and ``regress`` running one at another window
    (None when too few samples slide there). Kept: ``filt`` when no predicted bias exceeds
    :data:`BIAS_SHARE` of its standard error there. Otherwise windows grow by :data:`LADDER`
    (at most :data:`MAX_WINDOW` s and :data:`MAX_LOG_SHARE` of the log), or shrink by it
    where the bending outweighs the noise already (to the order's fewest samples), until
    the biases are within that share or J's changes sign, which :data:`BISECT` bisections
    then close in on; of the windows tried, the one of the smallest largest bias is
    returned, with its fit and its :func:`predicted_bias` (``widened_from`` or
    ``narrowed_from``: ``filt``'s window)."""
    record = predicted_bias(series, filt, fit[3], fit[2], model)
    if record is None or _worst(record) <= BIAS_SHARE:
        return filt, fit, record
    rate = 1.0 / series.dt
    tried = [(filt, fit, record)]
    narrower = record["relative"] > 0  # the bending outweighs the noise already
    step = 1.0 / LADDER if narrower else LADDER
    key = "narrowed_from" if narrower else "widened_from"

    def attempt(window: float) -> bool:
        """Regress at ``window``; whether the ladder or bisection can go on."""
        other = replace(filt, window=window)
        again = regress(other)
        if again is None:
            return False
        rec = predicted_bias(series, other, again[3], again[2], model)
        rec[key] = filt.window
        tried.append((other, again, rec))
        return _worst(rec) > BIAS_SHARE

    longest = min(MAX_WINDOW, MAX_LOG_SHARE * series.time.size * series.dt)
    shortest = (filt.order + 2) / rate

    def within(window: float) -> bool:
        differs = replace(filt, window=window).samples(rate) != tried[-1][0].samples(rate)
        return shortest <= window <= longest and differs

    window = filt.window
    while within(window * step) and attempt(window * step):
        window *= step
        if (tried[-1][2]["relative"] > 0) != narrower:  # past the crossing: bisect back
            low, high = sorted((window / step, window))
            for _ in range(BISECT):
                mid = np.sqrt(low * high)
                if replace(filt, window=mid).samples(rate) in {
                    replace(filt, window=w).samples(rate) for w in (low, high)
                } or not attempt(mid):
                    break
                low, high = (mid, high) if tried[-1][2]["relative"] < 0 else (low, mid)
            break
    return min(tried, key=lambda t: _worst(t[2]))


def corrected(stage, record: dict[str, Any] | None):
    """``stage`` less its predicted biases (``record``, :func:`predicted_bias`), each standard
    error widened by :data:`CORRECTION_ERROR` of its correction (in quadrature) and each
    interval by the same factor about the corrected value, within the search box;
    ``record["applied"]`` set. Not for a parameter whose interval reaches the box
    (``record["not_applied"]``): a stribeck delta with a standard error of 25 in [0.2, 4]
    had been moved by 31 to the far bound, its interval [0.2, 0.2]."""
    if record is None:
        return stage
    b = np.array([record["parameters"][n] for n in stage.names])
    box = stage.bounds
    bounded = (stage.low > box[:, 0]) & (stage.high < box[:, 1])
    b = np.where(bounded, b, 0.0)  # an interval at the box: the data bound neither it nor this
    record["not_applied"] = [n for n, ok in zip(stage.names, bounded, strict=True) if not ok]
    se = np.sqrt(stage.stderr**2 + (CORRECTION_ERROR * b) ** 2)
    with np.errstate(invalid="ignore", divide="ignore"):
        grow = np.where(stage.stderr > 0, se / stage.stderr, 1.0)
    values = np.clip(stage.values - b, stage.bounds[:, 0], stage.bounds[:, 1])
    low = np.maximum(values - (stage.values - stage.low) * grow, stage.bounds[:, 0])
    high = np.minimum(values + (stage.high - stage.values) * grow, stage.bounds[:, 1])
    cov = stage.cov + np.diag((CORRECTION_ERROR * b) ** 2)
    record["applied"] = True
    return replace(stage, values=values, stderr=se, low=low, high=high, cov=cov)


def bias_caveat(record: dict[str, Any] | None) -> str:
    """The caveat (and a :class:`DerivativeBiasWarning`) when a correction's own error, a
    :data:`CORRECTION_ERROR` share of it, exceeds the parameter's standard error before it
    (the interval is then more the correction's than the data's); '' otherwise."""
    if record is None:
        return ""
    skipped = set(record.get("not_applied", ()))
    over = {
        n: r
        for n, r in record["over_stderr"].items()
        if CORRECTION_ERROR * r > 1.0 and n not in skipped
    }
    if not over:
        return ""
    named = ", ".join(f"{n} {record['parameters'][n]:+.3g} ({r:.1f} se)" for n, r in over.items())
    text = (
        f"the derivative window ({1e3 * record['window']:.0f} ms) biases {named}: the "
        f"encoder's noise biases the inertia by {-100 * record['noise_share']:+.1f} %, the "
        f"filter's bending of the motion by {100 * record['distortion']:+.2f} %; corrected, "
        "and a quarter of each correction added to its standard error"
    )
    warnings.warn(text, DerivativeBiasWarning, stacklevel=user_stacklevel())
    return text
