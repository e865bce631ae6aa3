"""Sweeps on arms: every joint's friction samples with the whole arm's gravity removed.

:func:`extract_arm` runs the single-joint steps (BAS-RBFNN paper section 2: constant-velocity
segments, settling, outliers, set-points; :mod:`.segment`, :mod:`.accumulate`) on each joint of
a :class:`~fricid.samples.RobotLog`, with gravity computed from the whole configuration at
every sample (:mod:`.arm_gravity`):

1. each joint's steady passes, reduced to the moments of its base gravity regressor row and
   its torque (the rigid-body torque that is neither gravity nor the joint's own inertia is
   subtracted first, from the model: the velocity products ``C dq``, zero on a joint swept
   alone at constant speed, and the inertial coupling of other joints that accelerate
   during the sweep, from the logged acceleration or else the velocity's derivative);
2. the base gravity parameters and every (joint, set-point) friction identified jointly
   (:func:`~.arm_gravity.solve_levels`), or the URDF's parameters kept (``identify=False``);
3. each joint's torque with the identified gravity removed, extracted again by
   :func:`~.pipeline.extract` with ``gravity="none"``: friction samples per direction, the
   quality table and diagnostics, as for one joint; the samples' load is the gravity torque
   (eq. 12) averaged over each set-point's samples, with eq. 7's sign: ``tau_g = -g(q)``
   (the motor torque is ``tau_f - tau_g``, eq. 8).

The fit of step 2 takes the kept samples' unfiltered torque (the running median of
``median_window`` still decides which samples are kept): the filter correlates neighbouring
samples, and with few passes per set-point the cluster-robust standard errors cannot make up
for the ordinary ones counting them as independent. Measured on the double pendulum's
sweeps (30 seeds, 50 Hz, noise 0.01 N m): 95 % intervals covered 87 % of the set-point
frictions and 91 % of the gravity parameters with the filtered torque, 97 % and 94 % with the
unfiltered one.

The single-joint eq. 7 is the special case of a one-joint robot (:mod:`.arm_gravity`).
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import ConfigError, DataError, DataQualityWarning, user_stacklevel
from ..samples import RawLog, RobotLog
from ._gravity_mode import explicit_none_note
from .accumulate import Accumulator
from .arm_gravity import ArmGravityFit, arm_moments, solve_levels
from .arm_rows import at_levels, held_runs, with_load
from .arm_signals import acceleration, joint_chunks, named_pieces, velocities
from .bins import PositionBins
from .pipeline import VELOCITY_RTOL, ExtractionResult, extract
from .segment import cluster, iter_segments
from .steady import OUTLIER_SIGMAS, SETTLE_SIGMAS

if TYPE_CHECKING:
    from ..robot.model import RigidBodyModel

__all__ = ["ArmExtraction", "extract_arm"]

#: Rows of the configuration evaluated by one call of the rigid-body model.
CHUNK = 4096

#: How the note (and warning) begins when the sweeps barely tell gravity from friction.
CONFOUNDED = "the sweeps barely tell the arm's gravity from the friction"

#: ``samples.meta["extract"]["gravity"]`` of an arm extraction.
ARM_MODE = "arm"


@dataclass(frozen=True, eq=False)
class ArmExtraction(Mapping):
    """Every swept joint's :class:`~.result.ExtractionResult` (a mapping joint -> result) and
    the arm's gravity fit (:class:`~.arm_gravity.ArmGravityFit`)."""

    gravity: ArmGravityFit
    results: dict[str, ExtractionResult]

    def __getitem__(self, joint: str) -> ExtractionResult:
        return self.results[joint]

    def __iter__(self) -> Iterator[str]:
        return iter(self.results)

    def __len__(self) -> int:
        return len(self.results)

    def setpoints(self, joint: str) -> list[dict[str, Any]]:
        """One joint's per-direction samples as written (``by_direction``), a dict per row
        sorted by temperature and velocity: ``temperature``, ``velocity``, ``friction``,
        ``load``, ``count``, and from the arm fit's level of that row (the one whose friction
        and count it took) ``friction_se`` (the gravity parameters' error included) and
        ``passes``; NaN and 0 for a row no level matched one to one."""
        bd = self.results[joint].by_direction
        levels = self.gravity.joint_levels(joint)
        rows = []
        for i in range(len(bd)):
            count = None if bd.count is None else int(bd.count[i])
            match = [
                lv
                for lv in levels
                if lv["friction"] == float(bd.friction[i]) and lv["count"] == count
            ]
            rows.append(
                {
                    "temperature": float(bd.temperature[i]),
                    "velocity": float(bd.velocity[i]),
                    "friction": float(bd.friction[i]),
                    "friction_se": match[0]["friction_se"] if match else float("nan"),
                    "load": float(bd.load[i]),
                    "passes": match[0]["passes"] if match else 0,
                    "count": count,
                }
            )
        return sorted(rows, key=lambda r: (r["temperature"], r["velocity"]))

    def table(self) -> list[dict[str, Any]]:
        """One row per swept joint: set-points, samples, the range of |friction|, the largest
        |gravity torque| [N m] and the fit's residual RMS [N m]."""
        rows = []
        for joint, res in self.results.items():
            f = np.abs(res.by_direction.friction)
            rows.append(
                {
                    "joint": joint,
                    "set-points": len(self.gravity.joint_levels(joint)),
                    "samples": len(res.by_direction),
                    "friction min [N m]": float(f.min()),
                    "friction max [N m]": float(f.max()),
                    "gravity max [N m]": float(np.abs(res.by_direction.load).max()),
                    "residual [N m]": self.gravity.residual_rms.get(joint, float("nan")),
                }
            )
        return rows


def _robot_rows(model: RigidBodyModel, log: RobotLog) -> RobotLog:
    """The log's columns of the model's joints, in the model's order."""
    missing = [j for j in model.joints if j not in log.joints]
    if missing:
        raise DataError(
            f"the log has no column for joint(s) {', '.join(missing)} of the robot model; "
            f"its joints: {', '.join(log.joints)} (the gravity of every joint needs the whole "
            "configuration)",
            file=log.source,
        )
    return log.select(model.joints)


def _segment_rows(raw: RawLog, options: dict) -> np.ndarray:
    """The rows of the joint's candidate steady segments (:func:`~.segment.iter_segments`,
    found from the velocity alone): the only rows whose torque the extraction reads."""
    parts = [
        np.arange(seg.row, seg.row + len(seg.log))
        for seg in iter_segments(
            raw,
            velocity_tolerance=options["velocity_tolerance"],
            settle_time=options["settle_time"],
            min_samples=int(options["min_samples"]),
        )
    ]
    return np.concatenate(parts) if parts else np.zeros(0, dtype=np.intp)


def _joint_dynamics(model: RigidBodyModel, base, arm: RobotLog, ddq, j: int, rows):
    """At ``rows``: joint ``j``'s base gravity regressor row ``Y_b(q)[j]`` (R, m) and the
    rigid-body torque on it that is neither gravity nor its own inertia (R,): the velocity
    products ``C(q, dq) dq`` and the other joints' inertia ``sum_k!=j M_jk ddq_k``
    (:func:`.arm_signals.acceleration`). Its own inertia is left out: its steady part is at constant
    speed, and a derivative would only add noise."""
    w = np.empty((rows.size, base.rank))
    other = np.empty(rows.size)
    for a in range(0, rows.size, CHUNK):
        r = rows[a : a + CHUNK]
        q = arm.position[r]
        w[a : a + CHUNK] = base.columns(model.gravity_regressor(q))[:, j, :]
        acc = ddq[r].copy()
        acc[:, j] = 0.0
        tau = model.inverse_dynamics(q, arm.velocity[r], acc) - model.gravity_torque(q)
        other[a : a + CHUNK] = tau[:, j]
    return w, other


def _with_torque(raw: RawLog, torque: np.ndarray) -> RawLog:
    """``raw`` with its motor torque replaced (a channel position kept as such)."""
    meta = {**raw.meta, "position_source": raw.meta.get("position_source", "channel")}
    return replace(raw, torque=torque, current=None, torque_constant=None, meta=meta)


def _passes(raw: RawLog, w: np.ndarray, where: np.ndarray, options: dict) -> list:
    """The set-point records of one joint, each with the :func:`arm_moments` of its kept
    samples (``w`` the joint's regressor rows at its segment rows, ``where`` each log row's
    index into ``w``)."""

    def moments(seg, keep, tau):
        # the unfiltered torque: the running median correlates neighbouring samples, which the
        # ordinary standard errors would count as independent (module notes)
        rows = where[seg.row + np.flatnonzero(keep)]
        return arm_moments(w[rows], seg.log.motor_torque[keep])

    acc = Accumulator(
        PositionBins(),
        int(options["median_window"]),
        outlier_sigmas=options["outlier_sigmas"],
        settle_sigmas=options["settle_sigmas"],
        min_samples=int(options["min_samples"]),
        extra=moments,
    )
    for seg in iter_segments(
        raw,
        velocity_tolerance=options["velocity_tolerance"],
        settle_time=options["settle_time"],
        min_samples=int(options["min_samples"]),
    ):
        acc.add(seg)
    kinds = acc.classify()
    return [r for r, k in zip(acc.records, kinds, strict=True) if k == "setpoint"]


def _levels(joint: str, records: list, options: dict) -> list[dict]:
    """Each record's set-point (temperature, signed velocity) as a level dict."""
    v_label, v_set = cluster(
        np.array([r.speed for r in records]), options["velocity_rtol"], relative=True
    )
    t_label, t_set = cluster(
        np.array([r.temperature for r in records]), options["temperature_atol"], relative=False
    )
    return [
        {
            "joint": joint,
            "temperature": float(t_set[it]),
            "velocity": float(v_set[iv]) * r.direction,
            "direction": int(r.direction),
        }
        for r, it, iv in zip(records, t_label, v_label, strict=True)
    ]


def extract_arm(
    log: RobotLog,
    model: RigidBodyModel,
    *,
    joints: Sequence[str] | None = None,
    identify: bool = True,
    temperature: float | None = None,
    median_window: int = 5,
    velocity_tolerance: float = 0.05,
    settle_time: float = 0.1,
    min_samples: int = 20,
    velocity_rtol: float = VELOCITY_RTOL,
    temperature_atol: float = 1.0,
    outlier_sigmas: float | None = OUTLIER_SIGMAS,
    settle_sigmas: float | None = SETTLE_SIGMAS,
) -> ArmExtraction:
    """Every swept joint's friction samples, with gravity from the whole configuration.

    Parameters
    ----------
    log : RobotLog
        Constant-velocity sweeps: each joint swept at constant speeds in both directions while
        the others are held (or move); it must hold every joint of ``model``.
    model : RigidBodyModel
        The arm (:meth:`fricid.robot.RigidBodyModel.from_urdf`); its masses are the starting
        point (``identify=True``) or the truth (``identify=False``).
    joints : sequence of str, optional
        The joints to extract (default every joint of the model with a steady sweep).
    identify : bool
        Identify the base gravity parameters from the sweeps (module :mod:`.arm_gravity`);
        False keeps the URDF's.
    temperature : float, optional
        degC, when the log has no temperature.
    median_window, velocity_tolerance, settle_time, min_samples, velocity_rtol,
    temperature_atol, outlier_sigmas, settle_sigmas
        As for :func:`~.pipeline.extract`.

    Returns
    -------
    ArmExtraction
        Joint -> :class:`~.result.ExtractionResult` (its ``by_direction`` samples are the
        friction per direction, load = the joint's gravity torque), and ``gravity``.

    Raises
    ------
    DataError
        A joint of the model missing from the log; an asked-for joint without a steady
        sweep; no joint swept; the gravity not determined.
    ConfigError
        A joint asked for that the model does not have.
    """
    from ..robot.base import base_parameters

    options = {
        "median_window": median_window,
        "velocity_tolerance": velocity_tolerance,
        "settle_time": settle_time,
        "min_samples": min_samples,
        "velocity_rtol": velocity_rtol,
        "temperature_atol": temperature_atol,
        "outlier_sigmas": outlier_sigmas,
        "settle_sigmas": settle_sigmas,
    }
    wanted = tuple(model.joints if joints is None else joints)
    unknown = [j for j in wanted if j not in model.joints]
    if unknown:
        raise ConfigError(
            f"joint(s) {', '.join(unknown)} not in the robot model; it has "
            + ", ".join(model.joints)
        )
    arm, replaced, coarse = velocities(_robot_rows(model, log))
    for note in coarse:
        warnings.warn(note, DataQualityWarning, stacklevel=user_stacklevel())
    base = base_parameters(model, gravity_only=True)
    ddq = acceleration(arm)
    named = named_pieces(arm)
    found = {}
    for joint in wanted:
        j = model.joints.index(joint)
        raw = arm.joint(joint, temperature=temperature)
        if joint in replaced:
            raw = replace(raw, meta={**raw.meta, "velocity_from": "position"})
        rows = _segment_rows(raw, options)
        w, other = _joint_dynamics(model, base, arm, ddq, j, rows)
        torque = raw.motor_torque.copy()
        torque[rows] -= other
        raw = _with_torque(raw, torque)
        where = np.full(len(arm), -1, dtype=np.intp)
        where[rows] = np.arange(rows.size)
        records = _passes(raw, w, where, options) if rows.size else []
        if not records:
            if joints is not None:
                raise DataError(
                    f"joint {joint}: no constant-velocity sweep found (no steady segment)",
                    file=log.source,
                )
            continue
        found[joint] = (raw, rows, w, records)
    if not found:
        raise DataError("no joint of the robot log has a constant-velocity sweep", file=log.source)
    kept, held = held_runs({j: f[3] for j, f in found.items()}, asked=joints is not None)
    stats, keys, raws = [], [], {}
    for joint, records in kept.items():
        raw, rows, w, _ = found[joint]
        raws[joint] = (raw, rows, w)
        stats.extend(r.extra for r in records)
        keys.extend(_levels(joint, records, options))
    fit = _fit(stats, keys, base, model, identify, log.source)
    if held:
        fit = replace(fit, notes=(*fit.notes, *(f"{j}: {why}" for j, why in held.items())))
    for note in fit.notes:
        if note.startswith(CONFOUNDED):
            warnings.warn(note, DataQualityWarning, stacklevel=user_stacklevel())
    results = {
        joint: _joint_result(raw, rows, w @ fit.beta, fit, options, joint, named)
        for joint, (raw, rows, w) in raws.items()
    }
    return ArmExtraction(fit, results)


def _fit(stats, keys, base, model, identify, source) -> ArmGravityFit:
    """Solve for ``beta`` and the levels; the levels as dicts with their numbers."""
    tuples = [(k["joint"], k["temperature"], k["velocity"]) for k in keys]
    unique = list(dict.fromkeys(tuples))
    level = np.array([unique.index(t) for t in tuples], dtype=np.intp)
    prior = base.project(model.parameters())
    sol = solve_levels(np.array(stats), level, prior=prior, fixed=not identify, source=source)
    first = {t: keys[i] for i, t in reversed(list(enumerate(tuples)))}
    levels = []
    for i, t in enumerate(unique):
        levels.append(
            {
                **first[t],
                "friction": float(sol.level[i]),
                "friction_se": float(sol.level_se[i]),
                "load": -float(sol.level_load[i]),  # tau_g of eq. 8: minus g(q)
                "count": int(sol.count[i]),
                "passes": int(sol.passes[i]),
                # d friction / d beta = -regressor: the error every level shares
                "regressor": [float(x) for x in sol.level_regressor[i]],
            }
        )
    joint_of = np.array([t[0] for t in unique])
    residual = {
        j: float(np.sqrt(sol.rss[joint_of == j].sum() / sol.count[joint_of == j].sum()))
        for j in dict.fromkeys(joint_of)
    }
    notes = [_confounded(sol, joint_of, residual)] if identify else []
    notes = [n for n in notes if n]
    if identify and not sol.determined.all():
        names = [n for n, d in zip(base.names, sol.determined, strict=True) if not d]
        notes.append(
            "the sweeps do not determine the base gravity parameter(s) "
            + "; ".join(names)
            + ": the URDF's values are kept in the directions they leave free"
        )
    k = sol.level.size
    return ArmGravityFit(
        joints=tuple(model.joints),
        names=tuple(base.names),
        beta=sol.beta,
        beta_se=sol.beta_se,
        beta_urdf=prior,
        identified=bool(identify),
        levels=levels,
        residual_rms=residual,
        covariance=sol.covariance[k:, k:],
        notes=tuple(notes),
    )


def _confounded(sol, joint_of: np.ndarray, residual: dict[str, float]) -> str | None:
    """What to know when the gravity parameters' error alone moves some joint's set-point
    frictions by more than its samples' scatter (the sweeps barely tell gravity from
    friction), else None. On the sweeps of ``tests/_arm_sweeps.py`` (every joint swept with
    the others in three poses) it moved them by at most 0.07 of the scatter; sweeping only
    the double pendulum's first joint, by 12.8 times (joint 2's parameters confounded with
    the set-point frictions: 1.05 +- 1.8 N m for a true 0.066)."""
    k = sol.level.size
    wbar = sol.level_regressor
    shared = np.sqrt(np.maximum(np.einsum("ki,ij,kj->k", wbar, sol.covariance[k:, k:], wbar), 0))
    worst = []
    for joint in dict.fromkeys(joint_of):
        own = residual[joint]
        top = float(shared[joint_of == joint].max())
        if np.isfinite(top) and own > 0 and top > own:
            worst.append(f"{joint} by up to {top:.2g} N m ({top / own:.3g}x its scatter)")
    if not worst:
        return None
    return (
        CONFOUNDED + ": the gravity parameters' "
        "standard errors alone move the set-point frictions of " + ", ".join(worst) + "; "
        "those frictions are not determined. Sweep every joint over its range with the other "
        "joints in several poses, or keep the URDF's masses (--urdf-masses; "
        "identify=False) if they are right"
    )


def _joint_result(
    raw: RawLog,
    rows: np.ndarray,
    gravity: np.ndarray,
    fit: ArmGravityFit,
    options,
    joint: str,
    named: list[tuple[slice, str]],
) -> ExtractionResult:
    """One joint's samples: its torque with the arm's gravity removed (at ``rows``, its
    segments: the only rows read), extracted as a horizontal joint's, each recording of a
    joined log as its own source (``named``, :func:`.arm_signals.named_pieces`); the load
    column is the gravity torque of the matching level."""
    torque = raw.motor_torque.copy()
    torque[rows] -= gravity
    chunks = joint_chunks(_with_torque(raw, torque), named)
    res = extract(chunks, gravity="none", **options)
    levels = fit.joint_levels(joint)
    how = (
        "gravity from the whole configuration (base gravity parameters identified from the sweeps)"
        if fit.identified
        else "gravity from the whole configuration (the URDF's masses)"
    )
    notes = (*(n for n in res.notes if n != explicit_none_note("channel")), how)
    opts = {**res.options, "gravity": ARM_MODE}
    meta = {"extract": opts, "gravity": {**_joint_meta(fit, joint)}, "notes": list(notes)}
    samples, by_direction = (
        replace(
            with_load(at_levels(x, levels, options, combined=c), levels, meta, combined=c),
            source=raw.source,  # a joined log's name, not its first recording's
        )
        for x, c in ((res.samples, True), (res.by_direction, False))
    )
    return replace(res, samples=samples, by_direction=by_direction, options=opts, notes=notes)


def _joint_meta(fit: ArmGravityFit, joint: str) -> dict:
    """The fit's record for one joint's samples file: parameters and that joint's levels."""
    meta = fit.as_meta()
    meta["levels"] = [row for row in meta["levels"] if row["joint"] == joint]
    meta["residual_rms"] = meta["residual_rms"].get(joint)
    return meta
