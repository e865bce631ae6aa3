"""Identification from any trajectory: the joint's inertia, gravity and friction together.

One joint, measured position ``q``, velocity ``qd`` and motor torque ``u`` (or current and K),
with fricid's sign convention (:func:`fricid.sim.gravity_torque`; BAS-RBFNN paper eq. 6-7)::

    u = J qdd + f(qd, state) - (p_x cos q - p_y sin q)

(the issue writes ``+ p_x cos q - p_y sin q``: the same law with the gravity coefficients of
opposite sign; fricid keeps the extractor's, so the two paths give comparable numbers).

Derivatives for the regression by a zero-phase filter (:class:`DerivativeFilter`:
Savitzky-Golay by default, or Butterworth with ``filtfilt``); the ``filtered`` route's own
low-pass (:class:`ParallelFilter`); their settings go into the provenance.

Routes, recorded in the result's provenance (``provenance["trajectory"]``):

``filtered`` (parallel-filtered equation error; the default for LuGre, the route of Dahl)
    All seven LuGre parameters (or Dahl's four) with J, p_x, p_y at once, by the equation
    of motion on every sample, both sides filtered by one zero-phase low-pass and decimated
    (Gautier 1997; Gautier, Janot and Vandanjon 2013, IDIM-LS; Pham and Gautier 1991), the
    bristle state driven by the measured motion: no simulation of the joint, no windows, no
    guards
    (:mod:`._trajectory_filtered`, whose notes say how the bristle state is driven between
    samples and what that leaves at 1 kHz).
``regression`` (inverse dynamics)
    ``u - f_static(qd; theta) = J qdd - p_x cos q + p_y sin q`` on the samples that slide
    (``|qd| >= v_slide``, grown by half the filter window): linear in ``J, p_x, p_y``, which
    are projected out of every candidate's residual (variable projection, Golub and Pereyra
    1973) so the optimiser searches the friction parameters only, then recovered by least
    squares. It sees LuGre's steady state only ([CW95]: at constant velocity LuGre is the
    static Stribeck law with ``tau_v = sigma_2``); the route of the static models, and the
    start of the others.
``simulation`` (simulation error; in ``two_stage`` and ``joint``)
    The joint is simulated under the measured torque (:func:`fricid.models.lugre.
    simulate_joint`, ``n_sub`` sub-steps per sample) over windows around every low-speed
    stretch (``|qd| < v_window``), cut into segments of :data:`SEGMENT` seconds that restart
    from the measured motion while the bristle state carries on (multiple shooting;
    restarting z too from a force balance hid sigma_1 entirely:
    ``tests/identify/dynamic/test_trajectory.py``); residuals the simulated minus the measured
    position and velocity, each channel scaled by its RMS at the start.
``presliding`` (LuGre, a log that never slides; taken by the default when fewer than
    :data:`MIN_SLIDING` samples slide)
    sigma_0 and the pre-sliding damping (sigma_1 + sigma_2) by the output error of the joint
    simulated under the logged torque below break-away, the other parameters reported not
    determined, with the reasons (:mod:`._presliding`, :mod:`._presliding_fit`).

Which, and why. ``route="filtered"`` by default: it is the standard of robot identification
(IDIM) and, measured below, it determines every parameter, with intervals three to nine
times narrower than ``two_stage``, in half the time. ``two_stage`` (the static part from the
regression, then sigma_0 and sigma_1 by simulation error, the classic order of LuGre
identification: [CW95] section IV; Canudas de Wit and Lischinsky 1997; Altpeter 1999; the
first stage's uncertainty carried by the two-step covariance of Murphy and Topel (1985), and
:data:`REFINE` passes re-fitting the static part with LuGre's friction along the motion)
treats the friction of the slowly sliding samples as static although LuGre's bristles lag
there, and sees the Stribeck region only outside guards around the reversals; the filtered
route uses every sample with LuGre's own friction. ``route="joint"`` refines everything by
the simulation error from the two-stage estimate. ``static=`` (a ``stribeck`` fit from
sweeps) takes the static part from the sweeps; it runs ``two_stage`` (only J, p_x, p_y are
then regressed). Static models (``stribeck``, ``coulomb_viscous`` and their per-direction
``_asym`` forms) take the regression.
Dahl (:mod:`fricid.models.dahl`) takes the filtered route only, started from a
``coulomb_viscous`` regression (its steady state: tau_c, sigma_2 = the viscous coefficient),
sigma_0 searched as log10 as LuGre's; no rate-bias estimate (that simulation is LuGre's).

Uncertainty: cluster-robust covariances (:func:`._trajectory_data.cluster_covariance`; blocks
of ``cluster_time`` seconds, or the simulation windows), t quantiles with G - 1 degrees of
freedom; sigma_0 and sigma_1 are searched and their intervals formed on a log scale (asymmetric
intervals; the standard error shown is the delta method's). Every fricid optimiser works on
every route (through :func:`fricid.optim.minimize`; least-squares methods get the residuals);
LuGre's intervals are then widened, :func:`._outcome.widen_calibrated`.

Convergence: each stage's search is a problem of the problem protocol
(:class:`fricid.identify.problem.Problem`), and every stage whose estimate is reported is
certified as an analytic fit is (:func:`fricid.identify.static.convergence.certify`, a short
local least-squares polish from its result; a stage that only started a later search of all
its parameters is recorded, not polished: :func:`._outcome.converged`). A simulated stage's
least-squares search on its default budget is first carried on from the certificate's polish
while that polish still gains (:func:`fricid.identify.static.convergence.settle`: 21 of 108
fits on ``benchmarks/bench_lugre.py``'s logs were uncertified without it, 1 with it). When
one is not certified the fit warns (``ConvergenceWarning``) and withholds every standard
error and interval. Where ``w_s`` is not bounded below by the data, ``tau_s`` and ``delta``
are reported not determined (:func:`._result.unresolved_rise`). The polish adds its
evaluations to the time (on the virtual joint, 2 shared cores: 0.3-0.45 s on a ``two_stage``
fit of 1.0-1.1 s, 0-0.5 s on a ``filtered`` one of 3.3-3.5 s without the rate bias).

Passivity ([BO00], :func:`fricid.models.lugre.passivity_margin`) is checked at the estimate
and at the least favourable corner of the 95 % intervals, reported in the provenance, and
warned about (:class:`PassivityWarning`) when the estimate is not passive.

Calibration of the intervals before the widening (``benchmarks/calib_trajectory.py``, seeds 10-49,
60 s): the Monte-Carlo spread of the filtered route's estimates over the mean reported standard
error is 0.98-1.05 for the static part, J, p_x and p_y (coverage 37-39/40 each), 0.75 and 0.70 for
log10 sigma_0 and sigma_1 (40/40); 270/280 covered. The cluster jackknife (CR3) changed the
standard errors by 0.5-1.5 % and no coverage: CR1 is kept (:mod:`._trajectory_data`).

Rate bias and measurement (``rate_bias="warn"``, the default of the filtered route): the
break-away between samples biases sigma_0 up and sigma_1 down at 1 kHz (seeds 10-49, 60 s:
+2.9 % and -18 %; noise-free 20 s: +3.8 % and -21 %). The encoder's counts per revolution are
read from the position steps or given (``encoder_counts``, :mod:`._rate`). A simulation at
the estimate through that encoder (:mod:`._rate`) gives every parameter's bias, recorded and
warned about (:class:`RateBiasWarning`; not applied, it over-corrects sigma_1 by about half);
an interval it exceeds by a standard error is widened, one it biases grossly is flagged not
determined (:func:`._outcome.calibrate`); sigma_1 is flagged where it does not follow a moved
truth (:mod:`._response`). Where the encoder does not resolve the bristles' deflection at
break-away the filtered estimate is refined by the output error (:mod:`._output`, DIDIM);
the result names the estimator (``provenance["trajectory"]["estimator"]``).

What it recovers, before the calibrated widening (``benchmarks/bench_trajectory.py``, run for the
report: LuGre truth, 60 s multi-sine at 1 kHz, trajectory noise, ``lm``, seeds 0-4; coverage by the
closed 95 % intervals; shared 2-core machine). ``filtered``: every interval closed (sigma_1 too, at
the light damping ratio 0.05); covered sigma_0 4/5, sigma_1 5/5, sigma_2 4/5, tau_c 4/5, tau_s 3/5,
w_s 3/5, delta 3/5 (26/35); seed 0 tau_s 0.793 [0.781, 0.805], w_s 0.103 [0.099, 0.108], sigma_0
9.5e3 [8.5e3, 1.07e4], sigma_1 1.07 [0.72, 1.61]; static intervals overlapping the sweeps' 23/25;
3.8-5.5 s per identification with the rate bias (1.7-2.7 s of it; estimated sigma_0 +2.9 to +4.2 %,
sigma_1 -15 to -39 %), 1.0-2.5 s without. ``two_stage`` (``--route two_stage``): sigma_1 open on
3/5 seeds, covered 24/32 closed (tau_s 2/5), seed 0 tau_s 0.734 [0.674, 0.793], half-widths 3-9
times the filtered route's, overlap 19/25, 4.1-5.7 s. Seeds 0-4 are the unlucky ones: on seeds
10-59 (not the benchmark's, ``filtered``; ``python benchmarks/calib_trajectory.py --first 10
--seeds 50``) 336/350 intervals covered (96 %; every parameter 47-50/50; p_x 45/50, p_y 46/50), the
misses clustered on a few seeds where the Stribeck trio misses together (their estimates are
correlated), as on seeds 0-4. The cut-off: 20 Hz; at 40 and 60 Hz (seeds 10-29) the intervals
halved but sigma_0 was covered on 4/20 and 2/20 seeds: the bristle drive's error at 1 kHz
(:mod:`._trajectory_filtered`: noise-free, 20 s, sigma_0 +3.5 %, sigma_1 -20 %, the static part and
J within 1.5 per mille; at 10 kHz every parameter within 0.3 per mille) then exceeds the intervals.
With ``--sigma1 8`` (damping ratio 0.4; seeds 10-19) 69/70 covered, sigma_1's half-width 1.7 %.

A designed experiment for the Stribeck shape (:func:`fricid.sim.trajectory.slow_multisine`,
``bench_trajectory.py --experiment slow_multisine``: the same 60 s, its first half
constant-speed plateaus at 0.03-0.3 rad/s both ways, the multi-sine faded in for the
second). With the filtered route (seeds 10-19) it pins the static part: tau_s, w_s, delta
10/10 with half-widths 0.08 %, 0.23 %, 0.34 % (the multi-sine's: 1.5 %, 4 %, 3 %), sigma_2
and tau_c 9/10; sigma_0 8/10 (within 2 %), but sigma_1 5/10 (8-15 % low, half-widths 7-10 %):
the 1 kHz bristle drive's error, larger than those intervals. (With ``two_stage`` it biased
sigma_0 to about 3e4 and sigma_2 low, for a reason the earlier record left open.) The
default stays the plain multi-sine; the slow plateaus are the experiment for a precise static
part, and logging faster (or a bristle drive that follows the break-away within a period) is
what would make sigma_1 as precise.

This module is longer than 500 lines because these notes carry the measured record of what
a trajectory does and does not determine, which belongs beside the code that produces it.

References
----------
[CW95] C. Canudas de Wit, H. Olsson, K. J. Astrom, P. Lischinsky, IEEE TAC 40(3), 1995.
[BO00] N. Barabanov, R. Ortega, IEEE TAC 45(4), 2000.
K. M. Murphy, R. H. Topel, "Estimation and inference in two-step econometric models",
J. Business & Economic Statistics 3(4), 1985.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from ...errors import ConfigError, DataError
from ...fitted import FittedModel
from ...models import get_model, lugre
from ...samples import RawLog, check_trajectory_log
from ._data import (
    DerivativeFilter,
    check_dissipates,
    guarded_sliding,
    rest_share,
    sliding,
    uniform_series,
)
from ._direction import direction_caveat, per_direction, start_levels
from ._filtered import (
    ParallelFilter,
    best_start,
    dahl_start,
    filtered_route,
    lugre_asym_start,
    lugre_start,
)
from ._outcome import (
    RATE_BIAS,
    PassivityWarning,
    RateBiasWarning,
    calibrate,
    estimator,
    warn_rate_bias,
    widen_calibrated,
)
from ._output import needs_output_error
from ._output import output_error as _output_error
from ._presliding_fit import fit_presliding
from ._rate import measurement, torque_delay, warn_delay
from ._rate import rate_bias as _rate_bias
from ._response import follows, reidentifier, response_notes
from ._result import build_result
from ._routes import (
    DYNAMIC_MODELS,
    JOINT_PARAMS,
    LUGRE_LAWS,
    ROUTES,
    STATIC_MODELS,
    _regression,
    route_for,
)
from ._simroute import simulation_route
from ._window import DerivativeBiasWarning, choose_window, corrected

__all__ = [
    "ROUTES",
    "DerivativeBiasWarning",
    "DerivativeFilter",
    "ParallelFilter",
    "PassivityWarning",
    "RateBiasWarning",
    "fit_trajectory",
]

#: Fewest sliding samples (``|v| >= v_slide``, away from the stretches below it) for the
#: routes that identify the sliding friction; below it LuGre takes the pre-sliding route.
MIN_SLIDING = 50

#: Settings of the output-error step (``output_error=``).
OUTPUT_ERROR = ("auto", "on", "off")

#: Laws with one level for both directions, whose fit tests whether the friction differs by
#: direction (:func:`._direction.direction_caveat`).
SYMMETRIC = ("coulomb_viscous", "stribeck", "lugre", "dahl")

#: The Dahl static part, as named in the ``coulomb_viscous`` model.
_STATIC_OF_DAHL = {"f_c": "tau_c", "beta": "sigma_2"}


def fit_trajectory(
    log: RawLog,
    model: str = "lugre",
    method: str = "lm",
    *,
    route: str = "filtered",
    gravity: str = "fit",
    derivative: DerivativeFilter | None = None,
    parallel: ParallelFilter | None = None,
    v_slide: float = 0.02,
    guard: float = 0.2,
    v_window: float | None = None,
    static: FittedModel | None = None,
    n_sub: int = 4,
    cluster_time: float = 0.5,
    seed: int = 0,
    max_evals: int | None = None,
    rate_bias: str = "warn",
    encoder_counts: float | None = None,
    output_error: str = "auto",
    progress: Callable[[int, int, str], Any] | None = None,
) -> FittedModel:
    """Identify a joint's friction, inertia and gravity from a trajectory (module notes).

    Parameters
    ----------
    log : RawLog
        Time, position, velocity, torque (or current with K), temperature; any reader's.
    model : str
        ``lugre``, ``lugre_asym`` (its levels and viscous coefficient per direction) or
        ``dahl`` (dynamic), or a static model: ``stribeck``, ``coulomb_viscous`` or either
        per direction (``stribeck_asym``, ``coulomb_viscous_asym``).
    method : str
        Any fricid optimiser (:data:`fricid.optim.METHODS`), used by both routes.
    route : str
        ``filtered`` (default for LuGre: every parameter at once by the parallel-filtered
        equation error), ``two_stage``, ``joint`` (then every parameter by simulation
        error), ``regression`` (static models; the only route for them). With ``static=``
        the ``filtered`` route becomes ``two_stage``. Dahl and ``lugre_asym``: ``filtered``
        only.
    gravity : str
        ``fit`` (p_x, p_y estimated) or ``none`` (a horizontal joint).
    derivative : DerivativeFilter, optional
        The zero-phase derivative filter of the regression (default Savitzky-Golay, 21 ms,
        order 3).
    parallel : ParallelFilter, optional
        The ``filtered`` route's low-pass on both sides (default Butterworth 20 Hz, order 4).
    v_slide : float
        Speed [rad/s] above which a sample counts as sliding for the regression.
    guard : float
        Time [s] after a stretch below ``v_slide`` left out of the regression too (the
        bristles' transient and any stick-slip ringing after a reversal; at least half the
        derivative filter's window, which smears the acceleration's jumps). Measured on the
        virtual joint (multi-sine, 30 s, noise-free): with 0.1 s tau_c came out 0.2 % low,
        32 standard errors; with 0.2 s the bias was within one standard error.
    v_window : float, optional
        Speed [rad/s] below which the simulation route's windows open; default
        ``max(w_s, 2 v_slide)`` with w_s from the static part. Windows open
        :data:`WINDOW_BEFORE` before such a stretch and close :data:`WINDOW_AFTER` after it.
    static : FittedModel, optional
        A ``stribeck`` fit from constant-velocity sweeps: the static part is taken from it.
    n_sub : int
        Sub-steps per sample of the simulation route and of the ``filtered`` route's bristle
        state.
    cluster_time : float
        Block length [s] of the regression's cluster-robust covariance.
    seed, max_evals
        As for :func:`fricid.optim.minimize` (the budget is per stage).
    rate_bias : {"warn", "off"}
        ``warn`` (default): every parameter's bias by simulation at the estimate through
        the log's rate and encoder (:func:`._rate.rate_bias`), recorded in
        ``provenance["trajectory"]["rate_bias"]``, warned about (:class:`RateBiasWarning`)
        beyond :data:`RATE_BIAS_WARN` standard errors, intervals widened or flagged by it
        (:func:`._outcome.calibrate`), and sigma_1 flagged where it does not follow a moved
        truth (:mod:`._response`, ``provenance["trajectory"]["follows"]``); ``off`` skips it.
    encoder_counts : float, optional
        The encoder's counts per revolution; default: read from the position steps
        (:func:`._rate.encoder_quantum`; none when the steps share no quantum). Recorded
        in ``provenance["trajectory"]["encoder"]``.
    output_error : {"auto", "on", "off"}
        LuGre's filtered route: refine every parameter by the output error of the joint
        simulated along the measured motion (:mod:`._output`, DIDIM); ``auto`` (default) when
        the encoder is too coarse for the equation error at its estimate
        (:func:`._output.needs_output_error`). Recorded in
        ``provenance["trajectory"]["output_error"]``.
    progress : callable, optional
        ``progress(i, n, label)`` as the ``i``-th (0-based) of the route's ``n`` stages
        starts (the log's derivatives, the regression, the filtered or simulation route,
        the rate bias, the intervals); ``progress(n, n, "done")`` at the end.

    Returns
    -------
    FittedModel
        Named ``model``; parameters with standard errors and 95 % intervals; the routes, the
        filter, J, p_x, p_y with intervals, timings and passivity in
        ``provenance["trajectory"]``. Its ``predict`` is the steady-state friction.

    Raises
    ------
    ConfigError
        An unknown model, route, gravity option or method.
    DataError
        Too short a log, too few sliding, a reversed sign, or (LuGre) no low-speed stretch.
    """
    key = str(model).strip().lower()
    route = route_for(key, route, static is not None)
    if gravity not in ("fit", "none"):
        raise ConfigError(f"gravity must be 'fit' or 'none', got '{gravity}'")
    if output_error not in OUTPUT_ERROR:
        raise ConfigError(f"output_error must be auto, on or off, got '{output_error}'")
    if rate_bias not in RATE_BIAS:
        raise ConfigError(f"rate_bias must be 'warn' or 'off', got '{rate_bias}'")
    derivative, chosen = derivative or DerivativeFilter(), derivative is None
    t_start = time.perf_counter()
    say = _stages(key, route, rate_bias, progress)
    say("checking the log, derivatives")
    check_trajectory_log(log)  # holes, grid size, stuck torque: before any allocation
    series = uniform_series(log)
    rate = 1.0 / series.dt
    raw = (log.time, log.position, log.velocity) if series.resampled else None
    encoder = measurement(series.position, series.velocity, series.dt, encoder_counts, raw)
    vf, acc, mask, short, moving = guarded_sliding(
        series, derivative, v_slide, guard, key in STATIC_MODELS, MIN_SLIDING
    )
    slides, never = mask.sum() >= MIN_SLIDING, moving < MIN_SLIDING
    if key == "lugre" and route in ("filtered", "two_stage", "presliding") and never:
        if progress is not None:
            progress(1, 2, "pre-sliding route: sigma_0, sigma_1 (the log never slides)")
        fitted = fit_presliding(  # a log that never slides: sigma_0, sigma_1 only (its notes)
            log,
            series,
            encoder,
            method=method,
            seed=seed,
            max_evals=max_evals,
            cluster_time=cluster_time,
            n_sub=n_sub,
            parallel=parallel,
            static=static,
            v_slide=v_slide,
            gravity=gravity,
            t_start=t_start,
        )
        if progress is not None:
            progress(2, 2, "done")
        return fitted
    if route == "presliding" and slides:
        raise DataError(
            f"{int(mask.sum())} samples slide faster than {v_slide:g} rad/s: the pre-sliding "
            "route is for logs that never slide (route filtered or two_stage for this one)",
            file=log.source,
        )
    if not slides:
        raise DataError(
            f"only {int(mask.sum())} samples slide faster than {v_slide:g} rad/s away from the "
            f"slower stretches ({moving} before the guards): too few for the static friction",
            file=log.source,
        )
    static_of = {"lugre": "stribeck", "lugre_asym": "stribeck", "dahl": "coulomb_viscous"}
    static_model = get_model(static_of.get(key, key))
    fixed = None
    if static is not None:
        if static.model != "stribeck":
            raise ConfigError(f"static= must be a stribeck fit, got '{static.model}'")
        fixed = static.theta()
    cluster_n = max(round(cluster_time * rate), 1)
    check_dissipates(series, vf, acc, mask, cluster_n, log.source)
    say("regression: static friction, inertia, gravity")
    args = (static_model, gravity, method, seed, max_evals, cluster_n, fixed)

    def regress(filt: DerivativeFilter):  # the regression at a derivative window
        vf, acc, mask = sliding(series, filt, v_slide, guard, short=short)
        if mask.sum() < MIN_SLIDING:
            return None
        return (vf, acc, mask, *_regression(series, vf, acc, mask, *args))

    fit, window_bias = regress(derivative), None
    if key in STATIC_MODELS:  # J and the static law are the regression's (._window)
        say("derivative window: the encoder's noise in the acceleration")
        derivative, fit, window_bias = choose_window(
            series, derivative, fit, regress if chosen else lambda filt: None, static_model
        )
    vf, acc, mask, stage1, _theta_s, c, r1 = fit
    stage1, direction = corrected(stage1, window_bias), ("", "")
    if key in (*SYMMETRIC, "lugre_asym"):  # a per-direction law fits better? (._direction)
        asym = per_direction(series, derivative, vf, acc, mask, args, stage1)
        if key in SYMMETRIC:
            direction = direction_caveat(asym, key, stage1)
    stages = {"regression": stage1}
    rename = {"dahl": _STATIC_OF_DAHL}.get(key, lugre.STRIBECK_NAMES if key in LUGRE_LAWS else {})
    joint_vals = dict(zip(JOINT_PARAMS, [*list(c), 0.0, 0.0], strict=False))
    fits = [("regression", stage1)] if stage1.result is not None else []
    # the static part as the result states it: from the regression or the sweeps
    static_tab = {rename.get(n, n): v for n, v in stage1.table().items()}
    if static is not None:
        for n in static_model.param_names:
            p = static.parameters[n]
            static_tab[rename.get(n, n)] = {
                "value": p.value,
                "stderr": p.stderr,
                "ci95_low": p.ci95[0],
                "ci95_high": p.ci95[1],
            }
    final = dict(static_tab)
    bounds_out = {
        rename.get(n, n): list(b)
        for n, b in zip(stage1.names, stage1.bounds, strict=True)
        if n in static_model.param_names
    }
    sim_info: dict[str, Any] = {}
    notes: dict[str, str] = {}
    y, yhat = series.torque[mask], series.torque[mask] - r1
    if key in DYNAMIC_MODELS and not joint_vals["inertia"] > 0:
        row = stage1.table().get("inertia", {})
        raise DataError(
            f"the trajectory does not determine the inertia (J = {joint_vals['inertia']:.3g} "
            f"+/- {row.get('stderr', float('nan')):.2g} kg m^2): a single sine makes J qdd "
            "and the gravity torque collinear; excite several frequencies (a multi-sine or a "
            "chirp)",
            file=log.source,
        )
    if key in ("dahl", "lugre_asym") or (key == "lugre" and route == "filtered"):
        parallel = parallel or ParallelFilter()
        say(f"filtered route: every {'Dahl' if key == 'dahl' else 'LuGre'} parameter")
        if key == "lugre_asym":
            start, box, law = lugre_asym_start(stage1, static_tab, asym)
        else:
            start, box, law = (dahl_start if key == "dahl" else lugre_start)(stage1, static_tab)

        def search(x0):  # best_start runs it again from a falling curve where it rose
            rest = (gravity, method, seed, max_evals, cluster_time, n_sub, parallel)
            return filtered_route(series, x0, box, *rest, log.source, law=law)

        levels = None
        if key in LUGRE_LAWS:  # a falling start's levels (._direction.start_levels)
            levels = start_levels(series, derivative, vf, acc, mask, args, asym)
        stage, y, r = best_start(search, start, law.names, box, levels)
        yhat = y - r
        stages["filtered"] = stage
        fits.append(("filtered", stage))
        final.update(stage.table())
        bounds_out.update({n: list(b) for n, b in zip(stage.names, stage.bounds, strict=True)})
        sim_info = {"parallel_filter": parallel.describe(rate), "n_sub": int(n_sub)}
        refine = None
        if key in LUGRE_LAWS:
            say("output error, when the encoder is too coarse")
            decide = needs_output_error(stage, encoder, series.dt)
            decide["applied"] = output_error == "on" or (
                output_error == "auto" and decide["needed"]
            )
            sim_info["output_error"] = decide
            if decide["applied"]:
                args = (gravity, method, seed, max_evals, cluster_time, n_sub, parallel)

                def refine(data, start):  # from an estimate (the rate bias's truth)
                    return _output_error(data, start, *args)

                second = {n: row["value"] for n, row in static_tab.items()}  # regression's
                stage, y, r = _output_error(series, stage, *args, second)
                decide["starts_sse"] = stage.result.get("starts")
                yhat = y - r
                stages["output_error"] = stage
                fits.append(("output_error", stage))
                final.update(stage.table())
        if key in LUGRE_LAWS and rate_bias == "warn":
            say("rate bias, by simulation at the estimate")
            rb = _rate_bias(
                series, stage, box, gravity, method, seed, n_sub, parallel, encoder, refine
            )
            sim_info["rate_bias"] = rb
            notes = calibrate(stage, rb)
            final.update(stage.table())
            warn_rate_bias(stage, rb, notes)
            say("whether the estimate follows a shifted truth")
            again = reidentifier(
                refine is not None, box, gravity, method, seed, cluster_time, n_sub, parallel
            )
            check = follows(series, stage, encoder, parallel.cutoff, seed, again)
            sim_info["follows"] = check
            notes = {**notes, **response_notes(stage, check)}
        if key in LUGRE_LAWS:
            sim_info["calibration"] = widen_calibrated(stage, rest_share(series))
            final.update(stage.table())
        sim_info["torque_delay"] = torque_delay(series, stage, parallel, gravity, cluster_time)
        warn_delay(sim_info["torque_delay"])
    elif key == "lugre":
        say(f"{route} route: sigma_0, sigma_1 by simulation error")
        sim_info, static_tab = simulation_route(
            series,
            vf,
            acc,
            mask,
            {
                "stage1": stage1,
                "static": static,
                "rename": rename,
                "static_tab": static_tab,
                "joint_vals": joint_vals,
                "stages": stages,
                "fits": fits,
                "final": final,
                "bounds_out": bounds_out,
                "method": method,
                "seed": seed,
                "max_evals": max_evals,
                "n_sub": n_sub,
                "gravity": gravity,
                "route": route,
                "v_slide": v_slide,
                "v_window": v_window,
                "cluster_n": cluster_n,
            },
        )
    say("intervals, passivity")
    result = build_result(
        key,
        route,
        log,
        series,
        vf,
        y,
        yhat,
        n_joint=len(c),
        stages=stages,
        fits=fits,
        final=final,
        bounds_out=bounds_out,
        options={
            "method": method,
            "seed": seed,
            "max_evals": max_evals,
            "static": static,
            "derivative": derivative,
            "v_slide": v_slide,
            "gravity": gravity,
            "t_start": t_start,
            "rename": rename,
            "notes": notes,
            "window_bias": window_bias,
            "direction": direction,
        },
        sim_info={
            **sim_info,
            "encoder": encoder,
            "estimator": estimator(key, route, sim_info, window_bias is not None),
        },
    )
    say("done")
    return result


def _stages(
    key: str, route: str, rate_bias: str, progress: Callable[[int, int, str], Any] | None
) -> Callable[[str], None]:
    """``say(label)``: the next stage of the route, told to ``progress`` with its place
    (``i`` of ``n``: the log, the regression, the route's own stages, the intervals)."""
    n = 3
    if key in LUGRE_LAWS:
        n += 1 + (route == "filtered") * (1 + 2 * (rate_bias == "warn"))
    else:  # Dahl's filtered route; a static model's derivative window
        n += 1
    count = [0]

    def say(label: str) -> None:
        if progress is not None:
            progress(min(count[0], n), n, label)
        count[0] += 1

    return say
