"""Whole-arm identification from any trajectory: :func:`fit_arm`.

The inverse dynamic identification model with least squares (IDIM-LS, Gautier 1991; the
practice of Gautier, Janot and Vandanjon 2013, IEEE T-CST 21(2)), for real sensors:

1. the quantised position and the torque are low-passed by the same zero-phase filter and
   decimated (:mod:`._signals`: the cut-off from the log's rate, the motion's bandwidth
   and the encoder step);
2. the regressor is ``[Y_b | friction]``: the base columns of the rigid-body regressor
   (:func:`fricid.robot.base_parameters`) beside each joint's friction per direction
   (:mod:`._friction`), so inertial and friction parameters are solved together;
3. weighted least squares with each joint's noise from its residuals, the Stribeck shapes by
   variable projection, covariances robust to the residuals' correlation in time
   (:mod:`._solve`);
4. physical consistency (:mod:`._consistent`): the least-squares base parameters are
   kept when some physical standard parameters give them (within their noise), else the
   nearest physical ones replace them (and the friction is solved again given them);
5. a verdict per joint from held-out validation: the torque error on a second log (or on the
   last :data:`HELDOUT_SHARE` of the log) over the joint's noise, graded with
   :mod:`fricid.identify.trust`'s thresholds (``fricid.metrics.NOISE_RATIO``,
   :data:`fricid.identify.trust.MISS_RATIO`).

The estimator is IDIM-WLS (recorded in the result's provenance). Torques recorded in closed
loop carry the noise fed back by the controller into the motion, which biases least squares
and which the instrumental-variable step IDIM-IV (Janot, Vandanjon and Gautier 2014) removes;
it is not done here. A PD-tracked arm has another, larger bias, from its reversals: the
low-pass spreads a reversal (the joint sticking while the drive builds up torque, the Coulomb
step) over about a period of the cut-off, and the friction columns, computed from the
filtered velocity, do not follow it there. Measured on a PD-tracked double pendulum
(``make_pd_log`` of the tests: 10 Hz PD with inverse-dynamics feed-forward, 20 s at 1 kHz,
no torque disturbance, no noise): with the true parameters the residual within 0.1 s of a
reversal was 0.15-0.18 N m against the direction of motion, nil beyond 0.2 s, and the Coulomb
levels came out 2 to 6 standard errors low, the viscous ones 2 to 5 high, with or without
quantisation and disturbance. Rows within :data:`WINDOW_PERIODS` periods of the cut-off of a
slow or reversing sample can be left out (``reversal_window``, :func:`_moving`): it removes
that bias, and in open loop costs the Stribeck rise the rows it is seen on, so it is used
where the data show sticks: unless told, a first fit keeps those rows, and when a joint's
residuals near its reversals show the sticks' misfit (:func:`._rows.sticking`) the arm is
fitted again with the window (the provenance's ``closed_loop`` says which). How far a
stick's misfit reaches depends on the joint (the wrist's small inertias stick longest), so
each joint's window then grows from there to where its residuals no longer show it
(:mod:`._rows`), on the identification log and on the held-out one alike. Beyond the
window the stick's tail remains, small but in the direction of the friction columns: each
stop gets two nuisance columns that take it (:mod:`._sticks`, projected out of the joint's
rows), in the fit and in the held-out error. The IDIM-IV step for the fed-back noise remains
undone.

The torque's timing: a drive's logged command is held from one sample to the next, so it
acts half a sample period after the positions it is logged with; on a 5 Hz PD-tracked Panda
that half period left up to 2.5 times the filtered noise in the residual (with the true
parameters). The delay is estimated by least squares (:func:`_torque_delay`) unless given,
once more after the Stribeck shapes are found: with the starting shapes, the misfit at the
reversals is steep in time and leaks into the delay's column (open-loop truth, tuning seed
50, 30 s, no delay in the data: 0.069 samples with the starting shapes, 0.017 after them;
searching the shapes again after that (two more sweeps) moved the held-out errors by 0.02
or less, and is not done); the held-out error of joints 1 and 2 fell from
1.42 and 1.45 times the noise to 1.28 and 1.27).

What remains in closed loop (fricid's simulator, ``benchmarks/bench_robot.py --truth sim``:
a 5 Hz PD on 2^17-count encoders; its torque noise is logged, not fed back, so IDIM-IV's
bias does not arise there): with the true parameters the filtered residual of every joint
is within 0.2-0.6 times the filtered noise on the rows kept (the regressor filtered as the
torque, :mod:`._signals`); a joint crosses its Stribeck velocities in some milliseconds,
far below the low-pass's resolution, and the reversal window leaves most of those rows out,
so the Stribeck shapes are determined weakly (their intervals are the profile regions,
:func:`._solve.shape_profiles`) and predicted with errors the intervals carry but the
held-out ratio shows. Two guards keep such a shape from predicting nonsense: each excess
``tau_s - tau_c`` is held between zero and the largest torque the joint's drive applied
beyond gravity (:func:`._friction.excess_cap`, :func:`._solve.bounded_lstsq`), and a
direction whose rise the fitted rows see only through the low-pass from the slow rows left
out (:func:`._solve.unseen_rises`) gets no rise (not determined, and the verdict says so).
``benchmarks/results/robot.txt`` (block 2b) gives the held-out ratios before and after.

LuGre joints (``friction="lugre"`` or ``{joint: "lugre"}``): the arm is identified with each
at its steady state (``stribeck``), then each LuGre joint's seven parameters from every row of
its torque given the arm's base parameters (:mod:`._lugre`), their intervals the profile
likelihood's (:mod:`._lugre_profile`); the held-out error predicts that joint with its LuGre
law on every row.

This module is longer than 500 lines because these notes carry the measured record behind
each step of the fit, which the code below follows in order.
"""

from __future__ import annotations

import time as _time
from collections.abc import Mapping
from dataclasses import replace
from typing import Any

import numpy as np

from ....errors import DataError
from ....fitted.arm import LOAD_FAMILIES, ArmFit
from ....models import get_model
from ....optim import one_blas_thread
from ....robot import RigidBodyModel, base_parameters
from ....samples import RobotLog
from ._channels import channel_problems, check_live_torque, with_channel_problems
from ._consistent import consistent_parameters
from ._filter_cov import filter_correlation
from ._friction import NO_LOAD, excess_cap, friction_for
from ._grade import MIN_EFFECTIVE, grade, loose_levels, unseen_rise_reasons
from ._load import FROM_FIT, FROM_LOG, FROM_URDF, joint_load, log_load
from ._lugre import lugre_stage, stand_ins
from ._polish import polish_shapes
from ._records import friction_records, interval, mark_held, widen
from ._rows import (
    MIN_SPEED,
    VELOCITY_NOISE_FACTOR,
    adapted_windows,
    closed_loop_text,
    near_stops,
    stick_signature,
    sticking,
    still_text,
    stop_distance,
)
from ._rows import moving_rows as _moving
from ._signals import ArmSignals, prepare_signals
from ._solve import (
    arm_covariance,
    bounded_lstsq,
    excess_bounds,
    friction_block,
    lstsq,
    search_shapes,
    shape_profiles,
    shape_rows,
    stack,
    unseen_rises,
    wls,
)
from ._sticks import project_out, stick_columns

__all__ = ["HELDOUT_SHARE", "MIN_SPEED", "VELOCITY_NOISE_FACTOR", "fit_arm"]

#: The share of a single log held out for validation (its end).
HELDOUT_SHARE = 0.25
#: ``reversal_window`` for logs recorded in closed loop: rows this many periods of the
#: cut-off from a slow or reversing sample are left out (:func:`_moving`), at least; each
#: joint's window grows from there (:func:`._rows.adapted_windows`).
WINDOW_PERIODS = 1.0
#: The largest torque delay estimated [sample periods] (:func:`_torque_delay`).
MAX_DELAY = 2.0


def _log_arrays(log: RobotLog, model: RigidBodyModel) -> tuple[np.ndarray, ...]:
    missing = [j for j in model.joints if j not in log.joints]
    if missing:
        raise DataError(
            f"the log has no columns for joint(s) {', '.join(missing)} of the model "
            f"(log joints: {', '.join(log.joints)})",
            file=log.source,
        )
    sel = log.select(model.joints)
    return sel.time, sel.position, sel.motor_torque


def _signals(
    log: RobotLog, model, counts, cutoff, stops=False, load_model=None, part="the log"
) -> ArmSignals:
    t, q, tau = _log_arrays(log, model)
    inertia = None
    if cutoff is None:  # the mean diagonal of the mass matrix over the log
        rows = np.linspace(0, len(t) - 1, 25).astype(int)
        inertia = np.diagonal(model.mass_matrix(q[rows]), axis1=1, axis2=2).mean(axis=0)
    sig = prepare_signals(
        t,
        q,
        tau,
        counts=counts,
        cutoff=cutoff,
        inertia=inertia,
        source=log.source,
        stops=stops,
        part=part,
    )
    if load_model is None:
        return sig
    own = log_load(log, model.joints)  # the load families' load (._load)
    return replace(sig, full_load=own if own is not None else joint_load(load_model, q))


def _torque_delay(sig: ArmSignals, Yb, frictions, moving) -> float:
    """The torque's delay behind the positions [sample periods], by least squares: the
    torque's filtered change per sample is one more column, ``tau = Y theta + a dtau``
    (:meth:`._signals.ArmSignals.delayed`), clipped to :data:`MAX_DELAY`. A command held from
    one sample to the next (a drive's logged set point) acts half a period after its sample
    (``a = 0.5``); a torque measured at the sample instants has none."""
    st = stack(Yb, sig, frictions, moving)
    dtau = st.residualise(sig.dtau[st.row_time, st.row_joint])
    x = lstsq(np.column_stack([st.A, dtau]), st.y)
    return float(np.clip(x[-1], -MAX_DELAY, MAX_DELAY))


def _every_row(Yb, sig: ArmSignals, frictions, theta, shape) -> tuple[np.ndarray, list]:
    """The residual of ``theta`` on every row (``shape``: rows, joints), not only the fitted
    ones, and each joint's friction columns: what the stick tests read (:mod:`._rows`)."""
    every = stack(Yb, sig, frictions, np.ones(shape, dtype=bool))
    residual = np.zeros(shape)
    residual[every.row_time, every.row_joint] = every.y - every.A @ theta
    return residual, [friction_block(sig, jf, j) for j, jf in enumerate(frictions)]


def _predict(model, bp, beta, frictions, sig: ArmSignals, theta_f: list[np.ndarray], lugre):
    tau = sig.regressor(model, bp) @ beta
    for j, jf in enumerate(frictions):
        if j in lugre:  # its second stage's law (._lugre)
            tau[:, j] += lugre[j].predict(sig)
            continue
        cols = sig.parallel(sig.friction_columns(jf, j))
        tau[:, j] += cols @ np.nan_to_num(theta_f[j])
    return tau


def fit_arm(log: RobotLog, model: RigidBodyModel, **kwargs: Any) -> ArmFit:
    """Identify a whole arm (:func:`_fit_arm`, on one BLAS thread: the problems are small and
    threads only contend on a shared machine). With a load family and no load channel in the
    log, twice: the second time with the load of the first fit's arm (:mod:`._load`). LuGre
    joints' second stage (:mod:`._lugre`) runs on the pass whose first stage is kept."""
    with one_blas_thread():
        try:
            auto = kwargs.get("reversal_window") is None
            lugre = bool(stand_ins(model.joints, kwargs.get("friction", ""))[1])
            # LuGre's second stage once, on the pass whose first stage is kept (._lugre)
            fit = _fit_arm(log, model, second_stage=not auto, **kwargs)
            if auto:  # closed loop or not, from the sticks
                stuck = sticking(fit.provenance["stick_signature"])
                if stuck or lugre:
                    kwargs["reversal_window"] = WINDOW_PERIODS if stuck else 0.0
                    first = fit.provenance["stick_signature"]
                    fit = _fit_arm(log, model, **kwargs)
                    fit.provenance["stick_signature"] = first
                rises = ("stribeck", "lugre")
                rise = [fit.friction[j]["family"].startswith(rises) for j in model.joints]
                fit.provenance["closed_loop"] = closed_loop_text(stuck, model.joints, rise)
            else:
                told = "closed loop" if kwargs["reversal_window"] > 0 else "open loop"
                fit.provenance["closed_loop"] = f"given: {told}"
        except DataError as err:  # a unit or sign mistake can be why: say so
            raise with_channel_problems(err, log, model) from None
        values = fit.standard.get("values")
        if fit.provenance["load"] == FROM_URDF and values is not None:
            refined = model.with_parameters(np.asarray(values, dtype=float))
            again = _fit_arm(log, model, load_model=refined, **kwargs)
            for key in ("closed_loop", "stick_signature"):  # decided by the first fit
                again.provenance[key] = fit.provenance.get(key)
            fit = again
        return fit


def _fit_arm(
    log: RobotLog,
    model: RigidBodyModel,
    *,
    friction: str | Mapping[str, str] = "stribeck_asym",
    consistent: bool = True,
    encoder_counts: int | None = None,
    cutoff: float | None = None,
    validate: RobotLog | None = None,
    urdf: str | None = None,
    reversal_window: float | None = None,
    torque_delay: float | None = None,
    load_model: RigidBodyModel | None = None,
    second_stage: bool = True,
) -> ArmFit:
    """Identify a whole arm's base inertial parameters and every joint's friction.

    Parameters
    ----------
    log : RobotLog
        All joints of the model (more are ignored): positions, torques (or currents and
        torque constants), uniformly sampled.
    model : RigidBodyModel
        The arm from its URDF (:meth:`fricid.robot.RigidBodyModel.from_urdf`).
    friction : str or mapping
        A family of :data:`._friction.FAMILIES` or ``lugre`` (:mod:`._lugre`) for every
        joint, or joint -> family (others ``stribeck_asym``).
    consistent : bool
        Make the inertial parameters physical (:mod:`._consistent`).
    encoder_counts : int, optional
        Counts per revolution (else read from the position's smallest step).
    cutoff : float, optional
        The low-pass cut-off [Hz] (else chosen: :func:`._signals.choose_cutoff`).
    validate : RobotLog, optional
        A second log for held-out validation (else the last :data:`HELDOUT_SHARE` of ``log``).
    urdf : str, optional
        The URDF's name, for the provenance (default ``model.source``).
    reversal_window : float, optional
        Leave out the rows within this many periods of the cut-off of a slow or reversing
        sample (:func:`_moving`; :data:`WINDOW_PERIODS` for a log recorded in closed loop,
        where the joints stick at their reversals), or more where a joint's residuals show
        its sticks' misfit farther out (:mod:`._rows`; each joint's window is in the
        provenance); 0 uses the velocity threshold alone. None, the default, decides from
        the data: 0, and :data:`WINDOW_PERIODS` when a joint's residuals near its reversals
        show sticks (:func:`._rows.sticking`; the provenance's ``closed_loop`` says which).
    torque_delay : float, optional
        The torque's delay behind the positions [sample periods] (0.5 for a command held
        from one sample to the next); default estimated from the data (:func:`_torque_delay`).
    load_model : RigidBodyModel, optional
        The arm whose gravity torque is the load families' load where the log has no load
        channel (default ``model``, the URDF's parameters; :mod:`._load`).

    Returns
    -------
    ArmFit

    Raises
    ------
    DataError
        Joints missing from the log, a non-uniform or too short log, no joint moving, a
        torque (or current) with one value in every row (:mod:`._channels`).
    ConfigError
        An unknown friction family.
    """
    start = _time.perf_counter()
    reversal_window = float(reversal_window or 0.0)
    friction, lugre_names = stand_ins(model.joints, friction)  # LuGre: a second stage
    frictions = friction_for(
        model.joints, dict(friction) if isinstance(friction, Mapping) else friction
    )
    source = "second log" if validate is not None else "last quarter of the log"
    parts = ("the log", "the second log (held out)")
    check_live_torque(log, model.joints)
    problems = channel_problems(log, model)
    if validate is None:
        cut = int(len(log) * (1 - HELDOUT_SHARE))
        log, validate = log.slice(0, cut), log.slice(cut, len(log))
        parts = tuple(
            f"{p} of the log's {cut + len(validate)} samples"
            for p in ("the identified first three quarters", "the held-out last quarter")
        )
    stops = reversal_window > 0  # recorded in closed loop: the joints stick at reversals
    load_from = None
    if any(jf.load for jf in frictions):
        refined = load_model is not None
        load_model = load_model or model
        load_from = (
            FROM_LOG
            if log_load(log, model.joints) is not None
            else FROM_FIT
            if refined
            else FROM_URDF
        )
    sig = _signals(log, model, encoder_counts, cutoff, stops, load_model, parts[0])
    if any(jf.stribeck for jf in frictions):
        _, q, tau = _log_arrays(log, model)
        for jf, cap in zip(frictions, excess_cap(tau, model.gravity_torque(q)), strict=True):
            jf.excess_max = float(cap)
    for j, jf in enumerate(frictions):  # a load family's joint without load (._friction)
        jf.unloaded = jf.load and bool(np.abs(sig.full_load[:, j]).max() <= NO_LOAD)
    distance = None
    if reversal_window > 0:  # each stop's stick left to its own columns (._sticks)
        near = near_stops(sig)
        distance = stop_distance(sig, near)
        sig = replace(sig, stick=stick_columns(sig, near))
    moving = _moving(sig, reversal_window, distance)
    if not moving.any():
        raise DataError(still_text(sig, reversal_window), file=log.source)
    bp = base_parameters(model)
    Yb = sig.regressor(model, bp)
    n = model.n
    estimate_delay = torque_delay is None
    undelayed = sig
    if estimate_delay:
        torque_delay = _torque_delay(sig, Yb, frictions, moving)
    sig = undelayed.delayed(torque_delay)
    st = stack(Yb, sig, frictions, moving)
    theta, sigma = wls(st, n)
    windows = np.full(n, float(reversal_window))
    rho = filter_correlation(sig)  # the filters' own correlation of the rows
    if reversal_window > 0:  # each joint's own window, from how far its sticks' misfit reaches
        residual, columns = _every_row(Yb, sig, frictions, theta, moving.shape)
        windows = adapted_windows(distance, residual, reversal_window, columns, rho)
        moving = _moving(sig, windows, distance)
        st = stack(Yb, sig, frictions, moving)
        theta, sigma = wls(st, n)
    safe = np.where(np.isfinite(sigma) & (sigma > 0), sigma, 1.0)
    polish: dict[str, float] = {}
    if any(jf.stribeck for jf in frictions):
        search_shapes(sig, Yb, frictions, moving, safe)
        polish = polish_shapes(sig, Yb, frictions, moving, safe)  # all at once (._polish)
        if estimate_delay:  # again, with the shapes found (module notes)
            torque_delay = _torque_delay(undelayed, Yb, frictions, moving)
            sig = undelayed.delayed(torque_delay)
        unseen_rises(sig, frictions, moving)
        st = stack(Yb, sig, frictions, moving)
        theta, sigma = wls(st, n, excess_bounds(st, frictions))
        safe = np.where(np.isfinite(sigma) & (sigma > 0), sigma, 1.0)
    signature = None
    if reversal_window == 0:  # sticks at the reversals: a log recorded in closed loop?
        residual, columns = _every_row(Yb, sig, frictions, theta, moving.shape)
        signature = stick_signature(stop_distance(sig), residual, moving, columns, rho)
    A, y = st.weighted(safe)
    res = y - A @ theta
    stribeck = [j for j, jf in enumerate(frictions) if jf.stribeck]
    J = np.hstack([A, shape_rows(sig, frictions, st, theta, safe, stribeck)]) if stribeck else A
    bounds = excess_bounds(st, frictions)  # the Stribeck excesses' (._solve)
    held = [k for k, lo_hi in bounds.items() if theta[k] in lo_hi]
    J[:, held] = 0.0  # an excess held at a bound is no estimate (_records.mark_held)
    cov, se, t, clusters, corr_len, n_eff = arm_covariance(J, res, st, n, rho)
    r = bp.rank
    beta_ls = theta[:r]
    standard: dict[str, Any] = {"names": list(model.parameter_names)}
    beta = beta_ls
    if consistent:
        cons = consistent_parameters(beta_ls, cov[:r, :r], bp, model.parameters())
        standard.update(
            values=cons["pi"].tolist(),
            consistent_ls=cons["ls_consistent"],
            d2=cons["d2"],
            used="least squares" if cons["ls_consistent"] else "consistent",
        )
        if not cons["ls_consistent"]:
            beta = cons["beta"]
            # the friction given the consistent inertial parameters
            friction_bounds = {k - r: b for k, b in bounds.items()}
            fr = bounded_lstsq(A[:, r:], y - A[:, :r] @ beta, friction_bounds)
            theta = np.concatenate([beta, fr])
    units = {
        f: {p.name: p.unit for p in get_model(LOAD_FAMILIES.get(f, f)).parameters}
        for f in {jf.family for jf in frictions}
    }
    fric = friction_records(frictions, theta, cov, st, model.joints, t, sig, moving, units)
    mark_held(fric, frictions, st, theta, held, model.joints)
    inflation = np.bincount(st.row_joint, minlength=n) / np.maximum(n_eff, 1e-12)
    for (j, d), prof in shape_profiles(sig, Yb, frictions, moving, safe, inflation).items():
        widen(fric[model.joints[j]]["parameters"], d, prof, frictions[j].excess_max)
    lugre = {}
    if second_stage:  # else the fit is a first pass (fit_arm), its stand-ins reported
        lugre = lugre_stage(sig, Yb, beta, cov[:r, :r], lugre_names, model.joints, fric, sigma, rho)
    # held-out validation with the same filter
    vsig = _signals(validate, model, encoder_counts, sig.cutoff, stops, load_model, parts[1])
    vsig = vsig.delayed(torque_delay)
    vdistance = vstick = None
    if reversal_window > 0:
        vnear = near_stops(vsig)
        vdistance, vstick = stop_distance(vsig, vnear), stick_columns(vsig, vnear)
    vmoving = _moving(vsig, windows, vdistance)
    vmoving[:, list(lugre)] = True  # LuGre models the reversals (._lugre)
    pred = _predict(
        model,
        bp,
        beta,
        frictions,
        vsig,
        [theta[o : o + len(jf.linear_names)] for o, jf in zip(st.offsets, frictions, strict=True)],
        lugre,
    )
    err = vsig.tau - pred
    if vstick is not None:  # the held-out log's sticks reach as far as its motion makes them
        free = np.column_stack([project_out(err[:, j], vstick[j])[0] for j in range(n)])
        vcolumns = [friction_block(vsig, jf, j) for j, jf in enumerate(frictions)]
        vwindows = adapted_windows(vdistance, free, windows, vcolumns, filter_correlation(vsig))
        vmoving = _moving(vsig, vwindows, vdistance)
        vmoving[:, list(lugre)] = True
    validation = {}
    for j, name in enumerate(model.joints):
        e, lost = err[vmoving[:, j], j], 0
        if vstick is not None and j not in lugre:  # what no law predicts, as in the fit
            e, lost = project_out(e, vstick[j][vmoving[:, j]])
        rmse = float(np.sqrt(e @ e / max(e.size - lost, 1))) if e.size else float("nan")
        ratio = rmse / sigma[j] if np.isfinite(sigma[j]) and sigma[j] > 0 else float("nan")
        recs = fric[name]["parameters"]
        nd = [p for p, rec in recs.items() if rec["not_determined"]]
        open_ = [p for p, rec in recs.items() if rec["note"].startswith("not bounded")]
        loose = loose_levels(recs, float(sigma[j]), fric[name].get("load_range"))
        moved = bool(moving[:, j].any())
        level, reasons = grade(ratio, nd, open_, source, moved, loose, problems[name], n_eff[j])
        if moved and n_eff[j] < MIN_EFFECTIVE:  # no ratio from a noise of so few samples
            ratio = float("nan")
        reasons += lugre[j].reasons() if j in lugre else unseen_rise_reasons(frictions[j])
        validation[name] = {
            "rmse": rmse,
            "ratio": ratio,
            "source": source,
            "level": level,
            "reasons": reasons,
        }
    base_se = se[:r]
    return ArmFit(
        joints=model.joints,
        friction=fric,
        base={
            "names": list(bp.names),
            "values": beta.tolist(),
            "values_ls": beta_ls.tolist(),
            "stderr": base_se.tolist(),
            "ci95": [interval(b, s, t) for b, s in zip(beta, base_se, strict=True)],
            "determined": np.isfinite(base_se).tolist(),
        },
        standard=standard,
        noise={name: float(sigma[j]) for j, name in enumerate(model.joints)},
        validation=validation,
        provenance={
            "source": log.source,
            "urdf": urdf or model.source,
            "rate": sig.rate,
            "cutoff": sig.cutoff,
            "cutoff_bounds": sig.bounds,
            "filter": "Butterworth order 4, zero phase (filtfilt), parallel on the torque",
            "decimation": sig.decimation,
            "encoder_step": sig.encoder_step.tolist(),
            "estimator": "IDIM-WLS",
            "reversal_window": float(reversal_window),
            "windows": {nm: float(w) for nm, w in zip(model.joints, windows, strict=True)},
            "stick_columns": {nm: st.lost(j) for j, nm in enumerate(model.joints)},
            "torque_delay": float(torque_delay),
            "stick_signature": signature,
            "load": load_from,
            "shape_polish": polish,
            "stribeck_leaks": {
                nm: dict(jf.leaks) for nm, jf in zip(model.joints, frictions, strict=True)
            },
            "lugre": {lj.joint: lj.provenance for lj in lugre.values()},
            "samples": int(st.A.shape[0]),
            "effective_samples": {nm: float(x) for nm, x in zip(model.joints, n_eff, strict=True)},
            "correlation_length": corr_len,
            "clusters": clusters,
            "seconds": _time.perf_counter() - start,
        },
    )
