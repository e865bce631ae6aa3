"""Raw log to friction samples: the BAS-RBFNN paper's section 2 as one function, :func:`extract`.

1. Segment the constant-velocity portions (:mod:`.segment`) and group them into velocity and
   temperature set-points.
2. Median-filter the motor torque ``tau = K I`` (eq. 13) within each segment.
3. Bin by position and average over the repetitions (:mod:`.bins`).
4. Separate friction and gravity by eq. 11, fit eq. 7 and take the fitted gravity torque at
   each bin as its load (eq. 12) (:mod:`.gravity`); or, where the two directions do not cover
   the same positions, identify eq. 7 and each set-point's friction jointly
   (``gravity="joint"``, :mod:`.joint_gravity`); or, for a horizontal joint
   (``gravity="none"``, RWSAVSBAS paper section 2.1), take the torque as the friction.
"""

from __future__ import annotations

import logging
import warnings
from collections.abc import Iterable, Iterator
from dataclasses import replace

import numpy as np

from ..errors import ConfigError, DataError, DataQualityWarning, user_stacklevel
from ..samples import (
    NO_TEMPERATURE_SOURCE,
    RawLog,
    coarse_velocity,
    position_unit_problem,
    velocity_mismatch,
    windowed_velocity,
)
from ..samples._agreement import WINDOW_COUNTS
from ._gravity_mode import (
    AUTO,
    explicit_none_note,
    no_fit_note,
    residual_check,
    resolve,
    std_about_gravity,
)
from .accumulate import SPIKE_SIGMAS, Accumulator
from .bins import PositionBins, pool_cells
from .joint_gravity import JointGravityFit, fit_gravity_joint
from .quality import flag_scatter, warn_quality
from .result import Diagnostics, ExtractionResult
from .segment import SegmentCounts, as_log_stream, cluster, iter_segments
from .separation import assemble, sem_values
from .steady import OUTLIER_SIGMAS, SETTLE_SIGMAS

__all__ = ["GRAVITY_MODES", "SPIKE_SIGMAS", "Diagnostics", "ExtractionResult", "extract"]

logger = logging.getLogger(__name__)

#: Default ``velocity_rtol``: runs whose plateaus lie within 1 % of a set-point's centre are
#: repeats of it. Repeats of one commanded speed agree far closer (the virtual joint's within
#: 0.06 %; a drive tracks its command), while designs with closely spaced speeds (3 % apart, or
#: 0.1 deg/s steps up to 5 deg/s: 2 %) must stay apart.
VELOCITY_RTOL = 0.01

#: Values of ``extract(..., gravity=...)``.
GRAVITY_MODES = ("fit", "joint", "none")


class _Source:
    """Passes a log stream through, remembering the first log's source name, where its
    position came from (``meta["position_source"]``; a reader that integrates the velocity
    says so there, a position channel is assumed otherwise) and, per source, a logged
    velocity that is not its position channel's derivative (``problems``:
    :func:`fricid.samples.velocity_mismatch`, judged on each log or chunk that moves) and
    a coarse encoder's finite-difference velocity (``coarse``: judged on the first chunk);
    ``temperature_source`` is the first log's ``meta["temperature_source"]``, when it has one
    (:data:`fricid.samples.NO_TEMPERATURE_SOURCE`: the samples record no temperature)."""

    def __init__(self, logs: RawLog | Iterable[RawLog]) -> None:
        self.logs = logs
        self.name: str | None = None
        self.position_source: str | None = None
        self.temperature_source: str | None = None
        self.problems: dict[str, str] = {}
        self.units: dict[str, str | None] = {}  # per source: position_unit_problem's finding
        self.coarse: dict[str, str | None] = {}  # per source: coarse_velocity's finding
        self.window: dict[str, tuple[int, int]] = {}  # per coarse source: the windows used

    def coarse_findings(self) -> list[str]:
        """Per source whose velocity is a coarse encoder's finite difference, what is wrong and
        (where the position's slope replaced it) what was used instead."""
        out = []
        for source, coarse in self.coarse.items():
            if coarse and source in self.window:
                short, long = self.window[source]
                coarse = coarse.split(": it reads 0")[0] + (
                    "; the velocity used instead is the position's least-squares slope over "
                    f"windows of {short}-{long} rows each side, each spanning {WINDOW_COUNTS} "
                    "steps where the joint moves (a run's mean velocity is then close to its "
                    "position change over its duration)"
                )
            if coarse:
                out.append(f"{source}: {coarse}")
        return out

    def found(self) -> list[str]:
        """Every channel problem found, velocity's then position units'."""
        return [*self.problems.values(), *(u for u in self.units.values() if u)]

    def __iter__(self) -> Iterator[RawLog]:
        for log in as_log_stream(self.logs):
            meta = log.meta if isinstance(log.meta, dict) else {}
            if self.name is None:
                self.name = log.source
                self.position_source = str(meta.get("position_source", "channel"))
                self.temperature_source = meta.get("temperature_source")
            source = log.source or "the log"
            own = meta.get("position_source", "channel") == "channel"
            if own and "velocity_from" not in meta and source not in self.problems:
                wrong = velocity_mismatch(log.time, log.position, log.velocity)
                if wrong:
                    self.problems[source] = f"{source}: {wrong}"
            if own and source not in self.units:
                unit = position_unit_problem(log.position)
                self.units[source] = f"{source}: the position: {unit}" if unit else None
            if own and source not in self.coarse:
                self.coarse[source] = coarse_velocity(log.time, log.position, log.velocity)
                if self.coarse[source] and source not in self.problems:
                    self.window[source] = (np.inf, 0)
            if source in self.window:  # the position's slope over windows instead
                velocity, (short, long) = windowed_velocity(log.time, log.position, log.velocity)
                seen = self.window[source]
                self.window[source] = (min(seen[0], short), max(seen[1], long))
                log = replace(log, velocity=velocity, meta={**meta, "velocity_from": "position"})
            yield log
            del log  # not held while the next chunk is read


def velocity_from_position(log: RawLog) -> tuple[RawLog, str | None]:
    """``log`` with a coarse encoder's finite-difference velocity replaced by its position's
    least-squares slope (as :func:`extract` does), and the warning that says so (None when
    the velocity is kept): for callers that segment a log before :func:`extract` sees it
    (:func:`fricid.extract.arm.extract_arm`), so both read one velocity."""
    stream = _Source(log)
    (out,) = list(stream)
    found = stream.coarse_findings()
    return out, (found[0] if found else None)


def _check_options(median_window, gravity, velocity_rtol, temperature_atol) -> None:
    if int(median_window) != median_window or median_window < 1 or median_window % 2 == 0:
        raise ConfigError(
            f"median_window must be an odd positive integer (1: no filter), got {median_window!r}"
        )
    if gravity not in (*GRAVITY_MODES, AUTO):
        raise ConfigError(
            f"gravity must be one of {', '.join((*GRAVITY_MODES, AUTO))}; got {gravity!r}"
        )
    if not (velocity_rtol > 0):
        raise ConfigError(f"velocity_rtol must be > 0, got {velocity_rtol!r}")
    if not (temperature_atol > 0):
        raise ConfigError(f"temperature_atol must be > 0 degC, got {temperature_atol!r}")


def extract(
    logs: RawLog | Iterable[RawLog],
    *,
    positions=None,
    bin_halfwidth: float | None = None,
    median_window: int = 5,
    gravity: str = "fit",
    velocity_tolerance: float = 0.05,
    settle_time: float = 0.1,
    min_samples: int = 20,
    velocity_rtol: float = VELOCITY_RTOL,
    temperature_atol: float = 1.0,
    outlier_sigmas: float | None = OUTLIER_SIGMAS,
    settle_sigmas: float | None = SETTLE_SIGMAS,
) -> ExtractionResult:
    """Friction samples from raw constant-velocity sweeps (BAS-RBFNN paper, eq. 7-13).

    Parameters
    ----------
    logs : RawLog or iterable of RawLog
        One log or consecutive chunks of one (streamed; memory is bounded by a chunk plus one
        run). The torque is the logged torque or ``K I`` (eq. 13).
    positions : array_like, optional
        rad, centres of the position bins; None (default) makes each steady segment one bin
        (right for a horizontal joint or a steady-state file; needs ``gravity="none"``).
    bin_halfwidth : float, optional
        rad; default half the smallest spacing of ``positions``.
    median_window : int
        Samples of the running median applied to the torque within each segment (odd; 1
        disables it). It removes current spikes (section 2.2: "further filtered by median
        filtering").
    gravity : {"fit", "joint", "none", "auto"}
        "auto": remove gravity whenever the log can tell it: "fit" with position bins, else
        "joint" when the log has a position channel (falling back to "none" with a note when
        eq. 7 is not determined), else "none" with a note saying gravity was not removed.
        "fit": a joint with gravity, the paper's method; eq. 11 pairs both directions at every
        operating point, eq. 7 is fitted and gives the loads (eq. 12). Where a set-point lacks
        one direction in some bin, pairing is impossible and "joint" is used instead (with a
        note in ``notes``). "joint": eq. 7 and one friction per set-point and direction
        identified together by linear least squares over all steady samples
        (:func:`~.joint_gravity.fit_gravity_joint`); needs no pairing, nor position bins; a
        row with one direction is that direction's friction with gravity removed. "none": a
        horizontal joint; the torque is the friction, load 0; eq. 11 combines the directions
        where both exist, a single direction is used as measured; on a log with a position
        channel a note says that gravity was not removed.
    velocity_tolerance : float
        Relative band around a run's plateau velocity that counts as steady.
    settle_time : float
        s trimmed from each end of a steady part.
    min_samples : int
        Shortest steady part kept (also after the checks below).
    velocity_rtol : float
        Relative gap separating two velocity set-points, and the largest span of one relative
        to its centre (:func:`~.segment.cluster`: set-points cannot chain); default
        :data:`VELOCITY_RTOL`.
    temperature_atol : float
        degC gap separating two temperature set-points, and the largest span of one.
    outlier_sigmas : float or None
        Robust standard deviations beyond which a torque sample is an outlier and dropped
        (:func:`fricid.extract.steady.outliers`, default 8); None disables the screen.
    settle_sigmas : float or None
        Robust standard deviations of the settling test on velocity and torque
        (:func:`fricid.extract.steady.settled`, default 5); None keeps the whole steady part.

    Returns
    -------
    ExtractionResult
        With a per-set-point :class:`~fricid.extract.quality.QualityTable` (also in
        ``samples.meta["quality"]``, so it is written with the samples).

    Warns
    -----
    DataQualityWarning
        When samples were dropped as outliers or pinned at a rail, or a set-point's scatter is
        far above its neighbours' (:func:`fricid.extract.quality.warn_quality`).

    Notes
    -----
    What is averaged (issue 11): a run is *rest*, not a set-point, when its speed is below
    1e-3 of the fastest run's or it moved less than one encoder step (float residue of a held
    joint); a run whose steady part is mostly outside the velocity band (a return move, a move
    without a plateau) is *unsteady*; within a set-point's segment, leading and trailing
    stretches where velocity or torque have not settled are trimmed, samples pinned at the
    segment's extreme (a clipped sensor) and torque outliers are dropped. The quality table
    counts every sample's fate.

    Raises
    ------
    DataError
        No constant-velocity segment (the message counts the runs dropped, by reason); one
        direction only where eq. 11 needs two (it lists the set-points and the missing
        direction) when the joint fit cannot stand in either; a gravity fit without two
        distinct positions.
    ConfigError
        Bad options, among them ``gravity="fit"`` without ``positions``.
    """
    _check_options(median_window, gravity, velocity_rtol, temperature_atol)
    bins = PositionBins(positions, bin_halfwidth)
    requested = gravity
    if gravity == "fit" and bins.auto:
        raise ConfigError(
            "gravity='fit' needs position bins (positions=..., eq. 7 is fitted across them); "
            "without them each steady traverse is one bin, which suits a horizontal joint: "
            "gravity='none'"
        )
    stream = _Source(logs)
    counts = SegmentCounts()
    segments = iter_segments(
        stream,
        velocity_tolerance=velocity_tolerance,
        settle_time=settle_time,
        min_samples=min_samples,
        counts=counts,
    )
    acc = Accumulator(
        bins,
        int(median_window),
        outlier_sigmas=outlier_sigmas,
        settle_sigmas=settle_sigmas,
        min_samples=int(min_samples),
        moments=gravity != "none",
    )
    for seg in segments:
        acc.add(seg)
        del seg  # a view of its chunk: not held while the next chunk is read
    source = stream.name
    kinds = acc.classify()
    keep = kinds == "setpoint"
    if not keep.any():
        raise DataError(
            f"no constant-velocity segment found in {counts.rows} rows: {counts.runs} runs of one "
            f"velocity sign, {counts.dropped_short_run} shorter than min_samples={min_samples}, "
            f"{counts.dropped_no_plateau} without a velocity plateau, "
            f"{counts.dropped_short_steady} too short after trimming {settle_time} s of settling, "
            f"{int((kinds == 'rest').sum())} at rest (float residue or drift of a held joint), "
            f"{int((kinds == 'unsteady').sum())} without a steady plateau",
            file=source,
        )
    kept = [r for r, k in zip(acc.records, keep, strict=True) if k]
    notes: list[str] = []
    if gravity == AUTO:
        gravity, note = resolve(not bins.auto, stream.position_source)
    else:
        note = explicit_none_note(stream.position_source) if gravity == "none" else ""
    if note:
        notes.append(note)

    # set-points: velocity by relative gaps, temperature by absolute gaps
    v_label, v_set = cluster(np.array([r.speed for r in kept]), velocity_rtol, relative=True)
    t_label, t_set = cluster(
        np.array([r.temperature for r in kept]), temperature_atol, relative=False
    )
    shape = (t_set.size, v_set.size, bins.n_bins)
    cells = acc.table(keep, t_label, v_label, shape)
    measured = stream.temperature_source != NO_TEMPERATURE_SOURCE
    if not measured:  # the log's placeholder: one set-point, no temperature recorded
        t_set = np.full(t_set.size, np.nan)
    pooled = pool_cells(cells, int(np.prod(shape)) * 2)
    if not (pooled.count > 0).any():
        raise DataError(
            f"{len(kept)} constant-velocity segments found, but none has samples inside the "
            "position bins; check positions and bin_halfwidth (radians)",
            file=source,
        )
    options = {
        "positions": None if bins.auto else bins.centres.tolist(),
        "bin_halfwidth": bins.halfwidth,
        "median_window": int(median_window),
        "gravity": gravity,
        "velocity_tolerance": velocity_tolerance,
        "settle_time": settle_time,
        "min_samples": int(min_samples),
        "velocity_rtol": velocity_rtol,
        "temperature_atol": temperature_atol,
        "outlier_sigmas": outlier_sigmas,
        "settle_sigmas": settle_sigmas,
    }
    unflagged = acc.quality(
        kinds,
        t_label,
        v_label,
        t_set,
        v_set,
        cells,
        (counts.dropped_samples, counts.unsteady_samples),
    )
    if not measured:  # the rest and unsteady rows too
        unflagged = replace(unflagged, temperature=np.full(len(unflagged), np.nan))
    meta = {"extract": options, "quality": unflagged.rows()}
    forward = np.array([r.direction > 0 for r in kept], dtype=np.intp)
    group = (t_label * v_set.size + v_label) * 2 + forward

    def joint_fit() -> JointGravityFit:
        stats = np.array([r.moments for r in kept])
        return fit_gravity_joint(stats, group, 2 * forward - 1, source=source)

    try:
        samples, by_direction, fit, sem, direction_sem, position = assemble(
            pooled, shape, t_set, v_set, gravity, source, meta, joint_fit, notes
        )
    except DataError as exc:
        if requested != AUTO or gravity != "joint":
            raise
        notes.append(no_fit_note(exc.message))
        samples, by_direction, fit, sem, direction_sem, position = assemble(
            pooled, shape, t_set, v_set, "none", source, meta, joint_fit, notes
        )
    used = "none" if fit is None else ("joint" if isinstance(fit, JointGravityFit) else "fit")
    if used != requested:
        options["gravity_requested"] = requested
    options["gravity"] = used
    options["position_source"] = stream.position_source
    residual = residual_check(fit, kept, group, pooled, shape)
    if residual is not None:
        per = [residual.per_group.get(int(g), np.nan) for g in np.unique(group)]
        unflagged = unflagged.with_gravity_residual(per)
        if residual.message():
            notes.append(residual.message())
    if fit is not None and bins.auto:
        samples, by_direction, unflagged = _scatter_about_gravity(
            std_about_gravity(fit, kept, group), group, samples, by_direction, unflagged
        )
        sem, direction_sem = (
            np.array([np.nan if e is None else e for e in x.meta["sem"]], dtype=float)
            for x in (samples, by_direction)
        )
    quality = flag_scatter(unflagged)
    samples, by_direction = (
        replace(
            x,
            **({} if measured else {"temperature": None}),
            meta={
                **x.meta,
                "quality": quality.rows(),
                "extract": options,
                **({"notes": list(notes)} if notes else {}),
                **({"temperature_source": NO_TEMPERATURE_SOURCE} if not measured else {}),
                **({} if residual is None else {"gravity_residual": residual.as_meta()}),
                **({"channel_problems": stream.found()} if stream.found() else {}),
            },
        )
        for x in (samples, by_direction)
    )
    for note in notes:
        logger.info("%s", note)
    for coarse in stream.coarse_findings():
        warnings.warn(coarse, DataQualityWarning, stacklevel=user_stacklevel())
    for problem in stream.units.values():
        if problem:
            warnings.warn(
                f"{problem}; the samples' positions (and, in the same unit, velocities) are "
                "as logged and a model fitted on them is not trusted",
                DataQualityWarning,
                stacklevel=user_stacklevel(),
            )
    for problem in stream.problems.values():
        warnings.warn(
            f"the velocity is not the position's derivative, {problem}; the samples' "
            "velocities are as logged and a model fitted on them is not trusted",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
    passes = pooled.passes[pooled.count > 0]
    binned = int(sum(r.cells.count.sum() for r in kept))
    diagnostics = Diagnostics(
        rows=counts.rows,
        chunks=counts.chunks,
        runs=counts.runs,
        segments=len(kept),
        dropped={
            "short_run": counts.dropped_short_run,
            "no_plateau": counts.dropped_no_plateau,
            "short_steady": counts.dropped_short_steady,
            "rest": int((kinds == "rest").sum()),
            "unsteady": int((kinds == "unsteady").sum()),
        },
        spikes=sum(r.spikes for r in kept),
        binned=binned,
        outside_bins=sum(r.kept for r in kept) - binned,
        velocity_setpoints=v_set,
        temperature_setpoints=t_set,
        passes_min=int(passes.min()),
        passes_max=int(passes.max()),
        samples=quality.totals(),
    )
    warn_quality(quality, source, stacklevel=2, gravity=residual)
    logger.info("extracted %d samples from %d segments", len(samples), len(kept))
    return ExtractionResult(
        samples,
        by_direction,
        fit,
        diagnostics,
        sem,
        direction_sem,
        position,
        options,
        quality,
        tuple(notes),
    )


def _scatter_about_gravity(stats, group, samples, by_direction, quality):
    """With one bin per traverse, the rows' ``std`` and standard errors and the set-points'
    ``scatter`` about eq. 7 (``stats``: label -> (std, sem) [N m],
    :func:`._gravity_mode.std_about_gravity`), not about the mean torque, which holds
    gravity's range along the traverse. By-direction rows and set-point rows are in label
    order; a combined row pools its two directions (eq. 11 halves the standard error)."""
    labels = np.unique(group)
    new = np.array([stats.get(int(g), (np.nan, np.nan)) for g in labels])
    keep = np.isfinite(new[:, 0])
    d_std = np.where(keep, new[:, 0], by_direction.std)
    d_sem = np.where(keep, new[:, 1], np.asarray(by_direction.meta["sem"], dtype=float))
    d_meta = {**by_direction.meta, "sem": sem_values(d_sem)}
    by_direction = replace(by_direction, std=d_std, meta=d_meta)
    column = quality.scatter.copy()
    rows = np.flatnonzero(quality.setpoints)
    column[rows] = np.where(keep, new[:, 0], column[rows])
    quality = replace(quality, scatter=column)
    pair = labels // 2
    n = by_direction.count
    m2 = np.bincount(pair, weights=d_std**2 * np.maximum(n - 1, 0))
    total = np.bincount(pair, weights=n)
    k = np.bincount(pair)
    first = np.unique(pair)
    combined = np.sqrt(m2 / np.maximum(total - k, 1))[first]
    sem2 = np.bincount(pair, weights=d_sem**2)[first]
    sem = np.where(k[first] == 2, 0.5 * np.sqrt(sem2), np.sqrt(sem2))
    samples = replace(samples, std=combined, meta={**samples.meta, "sem": sem_values(sem)})
    return samples, by_direction, quality
