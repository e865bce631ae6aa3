"""Can I trust this model? The verdict a report opens with and the fleet's verdict columns.

Issue 11 ("Where it shows"): every consumer shows the diagnostics a model file carries. This
module reads them (and, where given, the samples) into one :class:`Trust`:

- data quality per set-point: kept and dropped samples, and why, from the samples'
  ``meta["quality"]`` (:class:`fricid.extract.QualityTable`), or a note that it is not
  recorded;
- convergence: the ``convergence`` block (:func:`fricid.identify.static.convergence.certify`), its
  reason and advice when the fit did not converge;
- identifiability: parameters not determined (each parameter record's flag: its note, or a
  NaN standard error) and intervals with an open end (the records' ``low_open``,
  ``high_open``); an open lower end at a bound of 0 means "consistent with zero" and is not a
  caveat;
- held-out error against the measurement scatter: the file's ``validation``; else (or when
  it is a learned model's own random-fold cross-validation, which tests the measured
  set-points only), given the samples, :func:`fricid.identify.validate` with ``lovo`` when
  the samples have at least :data:`MIN_LEVELS` velocity levels and it is small enough
  (:mod:`._heldout`: an analytic model's folds x samples x parameters at most
  :data:`VALIDATE_WORK`; a learned model's folds x samples at most
  :data:`fricid.identify.learned._trust.LEARNED_VALIDATE_WORK`, each fold retrained as
  ``fit`` trains it), so analytic and learned verdicts rest on the same test; else the
  learned model's own cross-validation, with the caveat, or the fit's in-sample
  ``rmse_over_scatter``, labelled as such;
- the operating range, outside which predictions are extrapolated.

The level is ``"no"`` when the fit did not converge, no free parameter is determined, or the
model misses the data by more than :data:`MISS_RATIO` times the scatter; ``"with caveats"``
when anything else above is short of clean (a parameter not determined or not bounded, an
error between :data:`fricid.metrics.NOISE_RATIO` and :data:`MISS_RATIO` times the scatter,
no held-out error or no scatter, convergence not recorded, set-points flagged for scatter or
with outliers dropped); ``"yes"`` otherwise. A model whose error misses the scatter gets
what to do (:func:`fricid.report.advice.misfit_advice`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..fitted import FittedModel, Parameter
from ..fitted._file import _convergence_line
from ..metrics import NOISE_RATIO, verdict
from ..samples import FrictionSamples
from ._heldout import MIN_LEVELS, VALIDATE_WORK, own_cv
from ._heldout import run_validation as _run_validation

__all__ = [
    "MIN_LEVELS",
    "MISS_RATIO",
    "VALIDATE_WORK",
    "Trust",
    "assess_trust",
    "not_determined",
    "open_sides",
    "range_text",
]

#: A model whose (held-out) RMSE exceeds this multiple of the measurement scatter is not
#: trusted: most of its error is the model's, not the noise's.
MISS_RATIO = 3.0

_UNITS = {"velocity": "rad/s", "load": "N m", "temperature": "degC"}


@dataclass
class Trust:
    """Whether to trust a model, and the diagnostics behind it (module notes).

    Attributes
    ----------
    level : str
        ``"yes"``, ``"with caveats"`` or ``"no"``.
    reasons : list of str
        Why, most severe first.
    converged : bool or None
        None when the file does not record it.
    convergence : str
        One line: converged (and how it was certified), or NOT converged with the reason.
    advice : str
        What to do about a fit that did not converge ("" otherwise).
    not_determined : list of str
        Free parameters the data do not determine.
    open_sides : dict of str to str
        Free parameters whose 95 % interval reaches a bound of the search box, with the note.
    heldout_ratio : float
        RMSE over the measurement scatter: held out when ``heldout_source`` is a scheme, else
        the fit's in-sample ratio (NaN when there is no scatter).
    heldout_rmse, scatter : float
        N m, the RMSE of that ratio and the scatter (NaN when unknown).
    heldout_source : str
        ``"lovo"``, ``"kfold:5"``, ... (held out), ``"in-sample"`` or ``""`` (none).
    verdict : str
        :func:`fricid.metrics.verdict` of the ratio.
    validation : dict or None
        The validation used (the file's, or the one run here: ``Validation.to_dict()``).
    validation_note : str
        Why no held-out error was computed here, or how it was ("" when from the file).
    range : str
        The extrapolation-free operating range, as text.
    quality : list of dict or None
        The samples' ``meta["quality"]`` rows, None when not recorded.
    quality_summary : str
        One line on them.
    rbf : bool
        The model is learned (the RBF network, the hybrid, the GP: no physical parameters
        to identify).
    cv : dict or None
        A learned model's own cross-validation record when the verdict is on another
        validation (shown beside it).
    what_to_do : str
        For a model whose error misses the scatter: what to do
        (:func:`fricid.report.advice.misfit_advice`); "" otherwise.
    model : str
        The model's registry name.
    """

    level: str
    reasons: list[str]
    converged: bool | None
    convergence: str
    advice: str = ""
    not_determined: list[str] = field(default_factory=list)
    open_sides: dict[str, str] = field(default_factory=dict)
    heldout_ratio: float = float("nan")
    heldout_rmse: float = float("nan")
    scatter: float = float("nan")
    heldout_source: str = ""
    verdict: str = ""
    validation: dict[str, Any] | None = None
    validation_note: str = ""
    range: str = ""
    quality: list[dict[str, Any]] | None = None
    quality_summary: str = ""
    rbf: bool = False
    cv: dict[str, Any] | None = None
    what_to_do: str = ""
    model: str = ""

    def line(self) -> str:
        """``"Trust: with caveats, because ..."``, and for a model that misses the data what
        to do (:func:`fricid.report.advice.misfit_advice`)."""
        out = f"Trust: {self.level}, because " + "; ".join(self.reasons) + "."
        return out + (f" What to do: {self.what_to_do}." if self.what_to_do else "")


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


def range_text(fitted: FittedModel) -> str:
    """The extrapolation-free operating range: ``"velocity 0.0105 to 0.838 rad/s; ..."``.

    Velocity of a model of combined samples (direction 0, odd in velocity) is given as speed
    ``|v|`` for either direction; one identified on one direction names it. Inputs the model
    does not use are left out; ``""`` when the file records no range.
    """
    used = set(fitted.inputs_used()) if fitted.operating_range else set()
    dirs = sorted({int(d) for d in (fitted.provenance or {}).get("directions") or ()})
    parts = []
    for name in ("velocity", "load", "temperature"):
        pair = fitted.operating_range.get(name)
        if not pair or name not in used:
            continue
        lo, hi = float(pair[0]), float(pair[1])
        unit = _UNITS[name]
        if name == "velocity" and dirs == [0]:
            parts.append(f"speed {lo:.4g} to {hi:.4g} {unit} (either direction)")
        elif name == "velocity" and dirs in ([1], [-1]):
            side = "positive" if dirs == [1] else "negative"
            parts.append(f"velocity {lo:.4g} to {hi:.4g} {unit} ({side} direction only)")
        elif lo == hi:
            parts.append(f"{name} {lo:.4g} {unit} only")
        else:
            parts.append(f"{name} {lo:.4g} to {hi:.4g} {unit}")
    return "; ".join(parts)


def _quality(samples: FrictionSamples | None) -> tuple[list[dict[str, Any]] | None, str, str]:
    """(rows, summary, caveat) of the samples' quality table."""
    rows = None if samples is None else samples.meta.get("quality")
    if not isinstance(rows, list) or not rows or not all(isinstance(r, dict) for r in rows):
        return None, "not recorded with these samples (no meta quality table)", ""
    points = [r for r in rows if r.get("kind", "setpoint") == "setpoint"]
    total = {k: sum(int(r.get(k) or 0) for r in rows) for k in _DROPS}
    kept = sum(int(r.get("kept") or 0) for r in points)
    flagged = [r for r in points if r.get("flagged")]
    dropped = ", ".join(f"{v} {_DROPS[k]}" for k, v in total.items() if v) or "none"
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


_DROPS = {
    "dropped_rest": "at rest",
    "dropped_transient": "transient",
    "dropped_outlier": "outliers",
    "dropped_saturated": "saturated",
}


def _point_name(row: dict[str, Any]) -> str:
    v = row.get("velocity")
    where = f"{v:.4g} rad/s" if isinstance(v, int | float) else "?"
    return f"{row['label']} ({where})" if row.get("label") else where


def _heldout(trust: Trust, fitted: FittedModel, samples: FrictionSamples | None) -> None:
    """The ratio to grade by: held out, else the file's in-sample ratio, else the in-sample
    ratio on ``samples`` (a network's file may not record its scatter)."""
    from ..identify.validate import measurement_scatter
    from ..metrics import rmse

    v = trust.validation
    if v and v.get("ratio") is not None:
        trust.heldout_ratio = float(v["ratio"])
        trust.heldout_rmse = float(v["rmse"]) if v.get("rmse") is not None else np.nan
        trust.scatter = float(v["scatter"]) if v.get("scatter") is not None else np.nan
        trust.heldout_source = str(v.get("scheme", "held out"))
    elif fitted.metrics.get("rmse_over_scatter") is not None:
        trust.heldout_ratio = float(fitted.metrics["rmse_over_scatter"])
        trust.heldout_rmse = float(fitted.metrics.get("rmse", np.nan))
        trust.scatter = float(fitted.metrics.get("scatter", np.nan))
        trust.heldout_source = "in-sample"
    elif samples is not None:
        sc = measurement_scatter(samples)
        if np.isfinite(sc.value) and sc.value > 0:
            trust.heldout_rmse = rmse(samples.y, fitted.predict(samples.X, warn=False))
            trust.scatter = sc.value
            trust.heldout_ratio = trust.heldout_rmse / sc.value
            trust.heldout_source = "in-sample"
    trust.verdict = verdict(trust.heldout_ratio)


def assess_trust(
    fitted: FittedModel,
    samples: FrictionSamples | None = None,
    *,
    run_validation: bool = True,
    max_work: int = VALIDATE_WORK,
) -> Trust:
    """Whether to trust ``fitted``, from its file and (optionally) its samples.

    Parameters
    ----------
    fitted : FittedModel
        The model, as loaded from its file.
    samples : FrictionSamples, optional
        The samples it was identified on: their quality table, and the held-out validation
        when the file has none.
    run_validation : bool, default True
        Run :func:`fricid.identify.validate` (``lovo``) when the file holds no validation, or
        only a learned model's own cross-validation, and the problem is small enough (module
        notes).
    max_work : int
        The size limit of an analytic model's validation (see :data:`VALIDATE_WORK`).

    Returns
    -------
    Trust
        The level and its reasons (module notes).
    """
    conv = fitted.convergence
    converged = fitted.converged
    if conv is None:
        line = "not recorded in this model file"
    elif converged:
        line = _convergence_line(conv)
    else:
        line = f"NOT converged: {conv.get('reason') or conv.get('message') or 'no reason given'}"
    rows, qsummary, qcaveat = _quality(samples)
    trust = Trust(
        level="yes",
        reasons=[],
        converged=converged,
        convergence=line,
        advice=str(conv.get("advice", "")) if conv is not None and not converged else "",
        not_determined=not_determined(fitted),
        open_sides=open_sides(fitted),
        validation=fitted.validation,
        range=range_text(fitted),
        quality=rows,
        quality_summary=qsummary,
        rbf=fitted.kind == "rbf",
        model=fitted.model,
    )
    mine = own_cv(fitted.validation)
    if (mine or trust.validation is None) and samples is not None and run_validation and converged:
        val, trust.validation_note = _run_validation(fitted, samples, max_work)
        trust.validation = val or trust.validation
    elif trust.validation is None:
        trust.validation_note = "no held-out validation in the file; in-sample only"
    elif mine:
        trust.validation_note = "leave-one-velocity-out not run here; the fit's own CV only"
    if mine and trust.validation is not fitted.validation:
        trust.cv = fitted.validation
    _heldout(trust, fitted, samples)
    _grade(trust, fitted, qcaveat)
    if trust.converged is not False and trust.heldout_ratio > MISS_RATIO:
        from .advice import misfit_advice

        held = trust.validation if trust.heldout_source != "in-sample" else None
        trust.what_to_do = misfit_advice(fitted, held, trust.scatter, MISS_RATIO, samples)
    return trust


def _grade(trust: Trust, fitted: FittedModel, quality_caveat: str) -> None:
    """Set ``trust.level`` and ``trust.reasons`` (module notes)."""
    no, caveats = [], []
    free = fitted.free
    if trust.converged is False:
        no.append(f"the fit did NOT converge ({trust.advice or 'see the convergence block'})")
    elif trust.converged is None:
        caveats.append("convergence is not recorded in this model file")
    if free and len(trust.not_determined) == len(free):
        no.append("no parameter is determined by the data")
    elif trust.not_determined:
        caveats.append(f"not determined by the data: {', '.join(trust.not_determined)}")
    if trust.open_sides:
        caveats.append(f"not bounded by the data: {', '.join(trust.open_sides)}")
    ratio = trust.heldout_ratio
    kind = "held-out" if trust.heldout_source not in ("", "in-sample") else "in-sample"
    if np.isfinite(ratio) and ratio > MISS_RATIO:
        no.append(f"the {kind} error {trust.verdict} the measurement scatter")
    elif np.isfinite(ratio) and ratio > NOISE_RATIO:
        caveats.append(f"the {kind} error {trust.verdict} the measurement scatter")
    elif not np.isfinite(ratio):
        caveats.append("no measurement scatter to compare the error with")
    if np.isfinite(ratio) and kind == "in-sample" and not no:
        caveats.append("no held-out validation (in-sample error only)")
    elif np.isfinite(ratio) and own_cv(trust.validation) and not no:
        levels = str(trust.validation.get("scheme", "")).startswith("levels")
        caveats.append(
            "held out between the measured speeds only (the fit's own CV over whole speed "
            "levels; beyond them untested)"
            if levels
            else "held out at the measured velocity levels only (the fit's own random-fold CV; "
            "between and beyond them untested)"
        )
    if quality_caveat:
        caveats.append(quality_caveat)
    if no:
        trust.level, trust.reasons = "no", no + caveats
        return
    if caveats:
        trust.level, trust.reasons = "with caveats", caveats
        return
    held = f"{kind} error is within noise ({ratio:.2f}x the scatter)"
    det = "every parameter is determined" if free else "the network fits"
    trust.level, trust.reasons = "yes", [f"the fit converged, {det} and the {held}"]


# -- the report's section ------------------------------------------------------------------


def quality_frame(rows: list[dict[str, Any]]) -> Any:
    """The quality rows as a table: set-point, kept, dropped by reason, scatter, flag."""
    import pandas as pd

    out = []
    for r in rows:
        out.append(
            {
                "kind": r.get("kind", "setpoint"),
                "set-point": r.get("label") or "",
                "velocity [rad/s]": r.get("velocity"),
                "direction": r.get("direction"),
                "temperature [°C]": r.get("temperature"),
                "runs": r.get("runs"),
                "kept": r.get("kept"),
                **{f"dropped: {why}": r.get(k) for k, why in _DROPS.items()},
                "scatter [N m]": r.get("scatter"),
                "high scatter": "HIGH" if r.get("flagged") else "",
            }
        )
    return pd.DataFrame(out)


#: The identifiability line of a learned model.
_LEARNED_IDENT = {
    "rbf": "not applicable to the network's weights (not physical; see the bootstrap "
    "intervals of its predictions)",
    "hybrid": "the backbone's parameters are a starting shape, not identified values (the "
    "residual network absorbs what they miss); see the bootstrap intervals of its predictions",
    "gp": "not applicable to the process's hyperparameters (not physical; see its posterior band)",
}


def trust_text(trust: Trust) -> str:
    """The section's list: data quality, convergence, identifiability, held-out error,
    operating range (plain text with the report's small markup)."""
    lines = [f"- **Data quality**: {trust.quality_summary}."]
    conv = f"- **Convergence**: {trust.convergence}"
    if trust.advice:
        conv += f". What to do: {trust.advice}"
    lines.append(conv + ".")
    ident = []
    if trust.rbf:
        ident.append(_LEARNED_IDENT.get(trust.model, _LEARNED_IDENT["rbf"]))
    elif trust.converged is False:
        ident.append("not assessed: the fit did not converge")
    if trust.not_determined:
        ident.append(f"not determined: {', '.join(trust.not_determined)}")
    ident += [f"{n}: {note}" for n, note in trust.open_sides.items()]
    lines.append(
        "- **Identifiability**: "
        + ("; ".join(ident) if ident else "every free parameter is determined and bounded")
        + "."
    )
    if np.isfinite(trust.heldout_ratio):
        label = (
            f"held-out RMSE ({trust.heldout_source})"
            if trust.heldout_source != "in-sample"
            else "in-sample RMSE"
        )
        held = (
            f"{label} {trust.heldout_rmse:.3g} N m against a scatter of {trust.scatter:.3g} "
            f"N m: {trust.verdict}"
        )
    else:
        held = "no measurement scatter to compare with"
    if trust.validation_note:
        held += f" ({trust.validation_note})"
    cv = trust.cv or (trust.validation if own_cv(trust.validation) else None)
    if cv and cv.get("rmse") is not None:
        held += (
            f"; the fit's own cross-validation ({cv.get('scheme')}): {cv['rmse']:.3g} N m, "
            f"{cv.get('verdict', '')}: {cv.get('note', '')}"
        )
    if trust.what_to_do:
        held += f". What to do: {trust.what_to_do}"
    lines.append(f"- **Error against scatter**: {held}.")
    lines.append(
        f"- **Operating range** (predictions outside it are extrapolated): "
        f"{trust.range or 'not recorded'}."
    )
    return "\n".join(lines)
