"""What a model file and its samples say about trust before any validation: parameters the
data do not determine or bound, the operating range, the samples' quality table, and whether
gravity may be left in the friction (:func:`gravity_caveat`).

Helpers of :mod:`fricid.identify.trust` (the verdict), kept apart so that the verdict's module
stays readable; :func:`not_determined` is also the report's parameter table status.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ConfigError
from ..fitted import FittedModel, Parameter
from ..models._range import SIDES, coverage_text, gap_pairs, gaps_note
from ..models.gp import left_out
from ..samples import FrictionSamples
from ._scatter import LEVEL_RTOL, _repeat_groups, sample_weights

__all__ = [
    "DOWN_WEIGHT",
    "DROPS",
    "EXCESS_ALPHA",
    "EXCESS_RATIO",
    "LEFT_IN",
    "OWN_SEM",
    "STD_SQRT_COUNT",
    "RunExcess",
    "between_run_excess",
    "downweighted",
    "gravity_caveat",
    "listed_count",
    "not_determined",
    "open_sides",
    "quality_rows",
    "range_text",
    "recorded_caveats",
]

#: A sample whose weight under a robust loss is below this is reported as down-weighted and
#: left out of the error the verdict grades: soft_l1 ``1 / sqrt(1 + z^2)`` below it beyond
#: ``|z| = 2.83`` scales, huber ``min(1, 1 / |z|)`` beyond 3 (``z`` the residual over the
#: loss's scale, weighted as the fit weighs it), about 0.5 % of Gaussian noise either way.
DOWN_WEIGHT = 1.0 / 3.0

#: Repeated runs whose between-run scatter is more than this multiple of what their own
#: standard errors explain (``meta["sem"]``, else ``std / sqrt(count)``; significantly so)
#: differ in something the samples do not record (:func:`gravity_caveat`). Set from the
#: statistics, not from a benchmark: runs that differ by their noise alone give about 1, with a
#: 99.9 % upper limit of 2.3 at 3 degrees of freedom (the test then decides), 1.5 at 20 and
#: 1.3 at 60 (this floor then does).
EXCESS_RATIO = 2.0

#: Significance of that excess (a one-sided chi-square test of the between-run sum of squares).
EXCESS_ALPHA = 1e-3

#: How the caveats of :func:`gravity_caveat` begin; how a velocity mismatch's.
LEFT_IN = "gravity may be left in"
NOT_DERIVATIVE = "the log's velocity is not its position's derivative"

#: Down-weighted samples listed by name (the rest counted).
_LISTED = 5

_UNITS = {"velocity": "rad/s", "load": "N m", "temperature": "degC"}

#: The quality table's drop counts and what each dropped.
DROPS = {
    "dropped_rest": "at rest",
    "dropped_transient": "transient",
    "dropped_outlier": "outliers",
    "dropped_saturated": "saturated",
}


def not_determined(fitted: FittedModel) -> list[str]:
    """Free parameters the data do not determine (their record's flag: the note says so, "not
    determined", "not identified", or, from a converged fit without notes, the standard error
    is missing)."""
    if fitted.kind == "rbf":
        return []
    return [n for n, p in fitted.parameters.items() if p.not_determined and not p.fixed]


def _zero_floor(p: Parameter) -> bool:
    """Only the lower side is open, at a bound of 0: the parameter is consistent with 0."""
    return bool(p.low_open and not p.high_open and p.bounds is not None and p.bounds[0] == 0)


def open_sides(fitted: FittedModel, *, include_zero: bool = False) -> dict[str, str]:
    """Free parameters whose 95 % interval reaches a bound of the search box, with the note
    of the fit (or one made here); ``include_zero`` keeps those open only at a lower bound of
    0 ("consistent with zero")."""
    out = {}
    for name, p in fitted.parameters.items():
        sides = (p.low_open, p.high_open)
        if p.fixed or not any(sides):
            continue
        if _zero_floor(p) and not include_zero:
            continue
        which = " and ".join(s for s, o in zip(("lower", "upper"), sides, strict=True) if o)
        out[name] = p.note or f"{which} side reaches the search bound"
    return out


def recorded_caveats(fitted: FittedModel) -> list[str]:
    """Caveats of what the file records: ``"no speed measured between 1 and 4 rad/s (v > 0):
    the model is untested there"`` for the gaps between measured speeds
    (``provenance["speeds"]``, :func:`fricid.models._range.speed_coverage`: held-out
    validation leaves out measured levels, so it says nothing of a gap), then a trajectory
    fit's own (``provenance["trajectory"]["caveats"]``: :mod:`.dynamic._window`)."""
    coverage = (fitted.provenance or {}).get("speeds")
    parts = [
        f"between {a:.4g} and {b:.4g} rad/s ({label})"
        for side, label in SIDES.items()
        for a, b in gap_pairs(coverage, side)
    ]
    gaps = [f"no speed measured {', '.join(parts)}: the model is untested there"] if parts else []
    own = ((fitted.provenance or {}).get("trajectory") or {}).get("caveats")
    return gaps + ([str(c) for c in own] if isinstance(own, list) else [])


def range_text(fitted: FittedModel) -> str:
    """The extrapolation-free operating range: ``"velocity 0.0105 to 0.838 rad/s; ..."``.

    Velocity of a model of combined samples (direction 0, odd in velocity) is given as speed
    ``|v|`` for either direction; one identified on one direction names it; one identified on
    both, where the file records the measured speeds per direction (``provenance["speeds"]``),
    gives each direction's range (:func:`fricid.models._range.coverage_text`: ``"velocity
    v > 0: measured 0.217 to 20.84 rad/s (nothing between 2 and 5), v < 0: ..."``). The gaps
    between measured speeds are named in each case. Inputs the model does not use are left
    out; ``""`` when the file records no range.
    """
    used = set(fitted.inputs_used()) if fitted.operating_range else set()
    dirs = sorted({int(d) for d in (fitted.provenance or {}).get("directions") or ()})
    coverage = (fitted.provenance or {}).get("speeds")
    parts = []
    for name in ("velocity", "load", "temperature"):
        pair = fitted.operating_range.get(name)
        if not pair or name not in used:
            continue
        lo, hi = float(pair[0]), float(pair[1])
        unit = _UNITS[name]
        if name == "velocity" and dirs == [0]:
            gaps = gaps_note(coverage, "both")
            parts.append(f"speed {lo:.4g} to {hi:.4g} {unit} (either direction{gaps})")
        elif name == "velocity" and dirs in ([1], [-1]):
            side = "positive" if dirs == [1] else "negative"
            gaps = gaps_note(coverage, side[:3])
            parts.append(f"velocity {lo:.4g} to {hi:.4g} {unit} ({side} direction only{gaps})")
        elif name == "velocity" and len(coverage_text(coverage)) == 2:  # per direction
            parts.append("velocity " + ", ".join(coverage_text(coverage)))
        elif lo == hi:
            parts.append(f"{name} {lo:.4g} {unit} only")
        else:
            parts.append(f"{name} {lo:.4g} to {hi:.4g} {unit}")
    return "; ".join(parts)


def quality_rows(
    samples: FrictionSamples | None,
) -> tuple[list[dict[str, Any]] | None, str, str]:
    """(rows, summary, caveat) of the samples' quality table (``meta["quality"]``,
    :class:`fricid.extract.QualityTable`): rows None when not recorded."""
    rows = None if samples is None else samples.meta.get("quality")
    if not isinstance(rows, list) or not rows or not all(isinstance(r, dict) for r in rows):
        return None, "not recorded with these samples (no meta quality table)", ""
    points = [r for r in rows if r.get("kind", "setpoint") == "setpoint"]
    total = {k: sum(int(r.get(k) or 0) for r in rows) for k in DROPS}
    kept = sum(int(r.get("kept") or 0) for r in points)
    flagged = [r for r in points if r.get("flagged")]
    dropped = ", ".join(f"{v} {DROPS[k]}" for k, v in total.items() if v) or "none"
    summary = f"{len(points)} set-points, {kept} samples averaged; dropped: {dropped}"
    caveats = []
    if flagged:
        names = ", ".join(_point_name(r) for r in flagged[:4])
        caveats.append(
            f"{len(flagged)} set-point(s) with scatter far above their neighbours' ({names})"
        )
    if total["dropped_outlier"]:
        caveats.append(f"{total['dropped_outlier']} outlier sample(s) dropped")
    if flagged:
        summary += f"; {len(flagged)} flagged for high scatter"
    return rows, summary, "; ".join(caveats)


def _point_name(row: dict[str, Any]) -> str:
    v = row.get("velocity")
    where = f"{v:.4g} rad/s" if isinstance(v, int | float) else "?"
    return f"{row['label']} ({where})" if row.get("label") else where


def downweighted(
    fitted: FittedModel, samples: FrictionSamples | None
) -> tuple[np.ndarray | None, list[str]]:
    """The samples a robust fit (``--loss soft_l1`` or ``huber``) down-weighted, or a GP's
    training left out as gross errors.

    Parameters
    ----------
    fitted : FittedModel
    samples : FrictionSamples, optional
        The samples it was fitted to.

    Returns
    -------
    numpy.ndarray of bool (n,) or None
        True where the sample's robust weight is below :data:`DOWN_WEIGHT`; None for a fit by
        least squares, without samples, or when none (or half or more) is down-weighted.
    list of str
        The down-weighted samples by velocity, load and temperature with their residual in
        scales (the first few; then how many more).
    """
    if fitted.model == "gp" and samples is not None:
        return _left_out(fitted, samples)
    loss = (fitted.loss or {}).get("loss")
    scale = (fitted.loss or {}).get("f_scale")
    if samples is None or loss not in ("soft_l1", "huber") or not scale or scale <= 0:
        return None, []
    r = samples.y - fitted.predict(samples.X, warn=False)
    if (fitted.loss or {}).get("weights") == "std":
        with contextlib.suppress(ConfigError):  # else the fit could not have weighed them
            r = r * np.sqrt(sample_weights(samples, "std"))
    z = np.abs(r) / float(scale)
    huber = np.minimum(1.0, 1.0 / np.maximum(z, 1e-300))
    weight = 1.0 / np.sqrt(1.0 + z**2) if loss == "soft_l1" else huber
    low = weight < DOWN_WEIGHT
    if not low.any() or 2 * low.sum() >= low.size:
        return None, []
    rows = np.flatnonzero(low)[np.argsort(-z[low])]
    return low, _listed(
        [_sample_name(samples, int(i), f"residual {z[i]:.3g}x the loss's scale") for i in rows]
    )


def _left_out(fitted: FittedModel, samples: FrictionSamples) -> tuple[np.ndarray | None, list]:
    """The samples a GP's training left out as gross errors (``state["left_out"]`` of each
    process, :mod:`fricid.identify.learned.gp`), found in ``samples`` by velocity and
    friction."""
    low = np.zeros(len(samples.velocity), bool)
    for out in left_out(fitted.state):
        for v, f in zip(out.get("velocity") or (), out.get("friction") or (), strict=False):
            low |= np.isclose(samples.velocity, v, rtol=1e-12, atol=0) & np.isclose(
                samples.friction, f, rtol=1e-12, atol=0
            )
    if not low.any() or 2 * low.sum() >= low.size:
        return None, []
    rows = np.flatnonzero(low)
    off = samples.friction[rows] - fitted.predict(samples.X[rows], warn=False)
    return low, _listed(
        [
            _sample_name(samples, int(i), f"{e:+.3g} N m from the process trained without it")
            for i, e in zip(rows, off, strict=True)
        ]
    )


def _listed(names: list[str]) -> list[str]:
    """The first :data:`_LISTED` names, then how many more."""
    more = [f"and {len(names) - _LISTED} more"] if len(names) > _LISTED else []
    return names[:_LISTED] + more


def listed_count(names: list[str]) -> int:
    """How many samples a list of :func:`downweighted` names stands for."""
    if names and names[-1].startswith("and ") and names[-1].endswith(" more"):
        return len(names) - 1 + int(names[-1].split()[1])
    return len(names)


def _sample_name(samples: FrictionSamples, i: int, why: str) -> str:
    """``"sample 4: v = -0.0979 rad/s, load 0 N m, 25 degC (residual 12x the loss's scale)"``:
    the sample's place among the table's rows, counted from 1 (not the file's line, which
    header and comment lines shift)."""
    parts = [f"v = {samples.velocity[i]:+.4g} rad/s"]
    if np.isfinite(samples.load[i]):
        parts.append(f"load {samples.load[i]:.4g} N m")
    if np.isfinite(samples.temperature[i]):
        parts.append(f"{samples.temperature[i]:.4g} degC")
    return f"sample {i + 1}: {', '.join(parts)} ({why})"


def channel_problems(samples: FrictionSamples | None) -> list[str]:
    """Reasons for ``no`` that the samples show of their log's channels:

    - the extraction found a logged velocity that is not its position channel's derivative
      (``meta["channel_problems"]``, :func:`fricid.samples.velocity_mismatch`: a unit, a
      sign or a gear ratio), so the samples' velocities are off by the factor and so is every
      coefficient fitted on them; or a position in another unit than its label
      (:func:`fricid.samples.position_unit_problem`);
    - friction against the motion at most set-points (:func:`reversed_friction`): friction
      only dissipates, so the torque's (or current's) sign is reversed.
    """
    meta = samples.meta if samples is not None and isinstance(samples.meta, dict) else {}
    found = meta.get("channel_problems")
    found = found if isinstance(found, list) else []
    out = [p if "position: its steps" in p else f"{NOT_DERIVATIVE}: {p}" for p in found]
    reversed_ = reversed_friction(samples)
    return out + ([reversed_] if reversed_ else [])


def reversed_friction(samples: FrictionSamples | None) -> str:
    """A reason when friction opposes the velocity at more than half of the moving samples
    (friction only dissipates: the torque's or current's sign is reversed), else ``""``.
    Gravity left in can turn the friction of one direction at a few slow set-points; it does
    not turn most of them."""
    if samples is None or len(samples) == 0:
        return ""
    v, f = samples.velocity, samples.friction
    moving = v != 0
    against = int(np.sum(np.sign(f[moving]) == -np.sign(v[moving])))
    if not moving.any() or against <= 0.5 * int(moving.sum()):
        return ""
    return (
        f"the friction opposes the velocity at {against} of {int(moving.sum())} samples, and "
        "friction only dissipates: the torque's (or current's) sign is reversed; negate it "
        "(fricid extract --format epos --flip-sign, or the column) and extract again"
    )


def gravity_caveat(samples: FrictionSamples | None) -> list[str]:
    """Caveats that the friction may hold gravity torque (eq. 7 of the BAS-RBFNN paper,
    ``p_x cos q - p_y sin q`` at the joint's position ``q``), one line each, from what the
    samples carry.

    - Provenance: an extraction from a log with a position channel that did not remove
      gravity (``meta["extract"]``: ``gravity`` ``"none"``, ``position_source``
      ``"channel"``; its note in ``meta["notes"]``), or whose eq. 7 fit left a pattern along
      the position (``meta["gravity_residual"]["structured"]``).
    - The samples themselves: repeated runs of one operating point whose means differ more
      than :data:`EXCESS_RATIO` times what their standard errors explain (``meta["sem"]``,
      else ``std / sqrt(count)``), significantly (:func:`between_run_excess`). Friction at
      one speed, load and temperature is one number; gravity left in is an offset at each
      run's position, common to both directions, so runs at different positions differ by
      it. The scatter between the runs then holds it, and a model within that scatter is not
      shown to be within the noise. Drift or noise far more autocorrelated than
      ``std / sqrt(count)`` assumes do the same (the caveat says so), unless the runs' means
      differ more than the raw samples scatter.

    Without positions, provenance or a within-run noise, gravity left in at a fixed position
    is a constant offset that no data of friction against speed can tell from friction; no
    caveat is made of what cannot be seen.
    """
    if samples is None:
        return []
    out = []
    meta = samples.meta if isinstance(samples.meta, dict) else {}
    extract = meta.get("extract") if isinstance(meta.get("extract"), dict) else {}
    if extract.get("gravity") == "none" and extract.get("position_source") == "channel":
        out.append(
            f"{LEFT_IN}: the extraction did not remove it though the log has a position "
            "channel (gravity 'none'), so the friction includes any gravity torque"
        )
    residual = meta.get("gravity_residual")
    if isinstance(residual, dict) and residual.get("structured"):
        rms, noise = residual.get("pattern_rms"), residual.get("expected")
        size = f" ({rms:.3g} N m RMS against {noise:.2g} from noise)" if rms and noise else ""
        out.append(
            f"{LEFT_IN} in part: the extraction's gravity fit (eq. 7, one link) leaves a pattern "
            f"along the position{size}, e.g. gravity of other joints"
        )
    excess = between_run_excess(samples, EXCESS_ALPHA)
    if excess is None or excess.ratio <= EXCESS_RATIO or not excess.significant:
        return out
    if excess.beyond_std:
        seen = "; they differ more than the raw samples scatter, which no autocorrelation explains"
    elif excess.within == STD_SQRT_COUNT:
        seen = ", unless the noise is far more autocorrelated than std/sqrt(count) assumes"
    else:
        seen = ""
    explain = (
        "their std/sqrt(count) explains"
        if excess.within == STD_SQRT_COUNT
        else f"{excess.within} explain"
    )
    out.append(
        f"{LEFT_IN}: repeated runs at {excess.points} operating point(s) differ "
        f"{excess.ratio:.3g}x more than {explain}, so something the samples do not record "
        "changes between runs (the position, with gravity in the torque; drift)"
        f"{seen}; the scatter the error is graded against holds it"
    )
    return out


#: ``RunExcess.within`` when the rows' standard errors are ``std / sqrt(count)``.
STD_SQRT_COUNT = "std/sqrt(count)"

#: ... when they are the samples' own (``meta["sem"]``, e.g. autocorrelation-corrected).
OWN_SEM = "their own standard errors"


@dataclass(frozen=True)
class RunExcess:
    """How far repeated runs of one operating point differ beyond their own within-run noise.

    Attributes
    ----------
    ratio : float
        ``sqrt(SS / E[SS])``: ``SS = sum_g sum_(i in g) (y_i - ybar_g)^2`` over the repeated
        operating points ``g``, ``E[SS] = sum_g (1 - 1/n_g) sum_(i in g) se_i^2`` what it is
        when each run's mean carries only its own noise, of standard error ``se_i`` (about 1
        then).
    dof : int
        ``sum_g (n_g - 1)``: ``SS / E[SS]`` is about ``chi2(dof) / dof`` under that noise.
    points : int
        The operating points repeated.
    significant : bool
        ``SS / E[SS]`` exceeds the ``1 - alpha`` quantile of ``chi2(dof) / dof``.
    beyond_std : bool
        The runs' means scatter more than the raw samples themselves (``SS`` over
        ``sum_g (1 - 1/n_g) sum std_i^2``, at the same significance): the mean of correlated
        samples varies no more than one sample does, so no autocorrelation explains it.
    within : str
        Where ``se_i`` came from: :data:`OWN_SEM` (the samples' ``meta["sem"]``, given for
        every repeated row) or :data:`STD_SQRT_COUNT`.
    """

    ratio: float
    dof: int
    points: int
    significant: bool
    beyond_std: bool
    within: str = STD_SQRT_COUNT


def _run_errors(samples: FrictionSamples) -> tuple[np.ndarray, str]:
    """Each row's standard error: the samples' own ``meta["sem"]`` where every row has a
    positive one, else ``std / sqrt(count)`` (NaN where neither is positive)."""
    sem = samples.meta.get("sem") if isinstance(samples.meta, dict) else None
    if sem is not None:
        with contextlib.suppress(TypeError, ValueError):
            own = np.array([np.nan if x is None else x for x in sem], dtype=float)
            if own.shape == (len(samples),) and np.all(own > 0):
                return own, OWN_SEM
    ok = (samples.std > 0) & (samples.count > 0)
    se = np.where(ok, samples.std / np.sqrt(np.where(ok, samples.count, 1.0)), np.nan)
    return se, STD_SQRT_COUNT


def between_run_excess(
    samples: FrictionSamples, alpha: float = 1e-3, rtol: float = LEVEL_RTOL
) -> RunExcess | None:
    """The between-run scatter of repeated runs against their within-run standard errors.

    Parameters
    ----------
    samples : FrictionSamples
    alpha : float
        Significance of ``significant`` and ``beyond_std`` (one-sided chi-square tests).
    rtol : float
        Repeats as :func:`._scatter.measurement_scatter` finds them
        (:func:`._scatter._repeat_groups`).

    Returns
    -------
    RunExcess or None
        None when no operating point is repeated by runs that all carry a standard error
        (``meta["sem"]``, or a positive ``std`` and ``count``).

    Notes
    -----
    Friction at one speed, load and temperature is one number, so runs of one operating point
    differ by their noise alone. Runs whose means differ far beyond their within-run noise
    differ in something the samples do not record: the joint's position (gravity left in, eq.
    7 of the BAS-RBFNN paper, is an offset ``p_x cos q - p_y sin q`` at each run's position),
    drift, or noise far more autocorrelated than ``std / sqrt(count)`` assumes (a lower bound
    of the standard error; an autocorrelation-corrected ``meta["sem"]`` is used instead where
    the samples carry one).
    """
    from scipy.stats import chi2

    se, within = _run_errors(samples)
    group = _repeat_groups(samples, rtol)
    sizes = np.bincount(group)
    ok = np.bincount(group, weights=np.isfinite(se).astype(float)) == sizes
    rep = (sizes > 1) & ok
    sel = rep[group]
    if not sel.any():
        return None
    g, y, se, std = group[sel], samples.y[sel], se[sel], samples.std[sel]
    n = sizes[g].astype(float)
    mean = np.bincount(g, weights=y, minlength=sizes.size)[g] / n
    ss = float(np.sum((y - mean) ** 2))
    dof = int(np.sum(sizes[rep] - 1))
    expected = float(np.sum((1.0 - 1.0 / n) * se**2))
    bound = float(np.sum((1.0 - 1.0 / n) * std**2))
    if not (expected > 0 and np.isfinite(ss)):
        return None
    critical = float(chi2.ppf(1.0 - alpha, dof)) / dof
    significant = bool(ss / expected > critical)
    beyond = bool(bound > 0 and np.all(std > 0) and ss / bound > critical)
    ratio = float(np.sqrt(ss / expected))
    return RunExcess(ratio, dof, int(rep.sum()), significant, beyond, within)
