"""Can I trust this model? The one place the verdict is computed: :func:`assess_trust`.

``fricid fit``, the fleet (through :func:`fricid.workflow.fit_samples`) and ``fricid report``
all call :func:`assess_trust` and read the one record it returns, a :class:`Trust`; the report
renders it and the fleet's verdict columns are its fields, so neither recomputes anything. It
reads the model file (and, where given, the samples the model was identified on):

- data quality per set-point: kept and dropped samples, and why, from the samples'
  ``meta["quality"]`` (:class:`fricid.extract.QualityTable`), or a note that it is not
  recorded;
- convergence: the ``convergence`` block (:func:`fricid.identify.static.convergence.certify`),
  its reason and advice when the fit did not converge;
- identifiability: parameters not determined (each parameter record's flag: its note, or a
  NaN standard error) and intervals with an open end (the records' ``low_open``,
  ``high_open``); an open lower end at a bound of 0 means
  "consistent with zero" and is not a caveat;
- held-out error against the measurement scatter, from (``Trust.heldout_source``):
  :data:`FROM_FIT` (the fit's own held-out validation: ``fricid fit --validate``, the
  manifest's ``validate``, or ``--model auto``'s choice); else, given the samples,
  :data:`RUN_HERE` (:func:`fricid.identify.validate` with ``lovo``, when the samples have at
  least :data:`MIN_LEVELS` velocity levels and the problem is small enough:
  :mod:`._heldout`, an analytic model's folds x samples x parameters at most
  :data:`VALIDATE_WORK`, a learned model's folds x samples at most
  :data:`LEARNED_VALIDATE_WORK`, each fold retrained as ``fit`` trains it); else
  :data:`OWN_CV` (a learned model's own cross-validation, with its caveat); else
  :data:`IN_SAMPLE` (the fit's ``rmse_over_scatter``): an in-sample number is never labelled
  held out. Samples other than the model's own (a report of a model on a new recording) grade
  the model's own error on them (:data:`NEW_SAMPLES`), inside its operating range.
  Leave-one-velocity-out is graded on its interior folds (:data:`LOVO_INTERIOR`,
  :func:`._heldout.graded_rmse`: the slowest and fastest held-out levels are extrapolations).
  On tiny data (at most :data:`TINY_SAMPLES` samples) random folds are run too
  (:func:`._heldout.worse_kfold`) and the worse ratio graded (:data:`KFOLD_HERE` when theirs);
- the scatter: one estimated from second differences because nothing repeats is said so in
  the reasons (:data:`ESTIMATED`), whatever the level;
- the operating range, outside which predictions are extrapolated.

The level is ``"no"`` when the fit did not converge, no free parameter is determined, the
model misses the data by more than :data:`MISS_RATIO` times the scatter, or the samples
show a velocity that is not the position's derivative or friction against the motion
(:func:`._diagnostics.channel_problems`, which replace the misfit advice); ``"with caveats"`` when
anything else above is short of clean (a parameter not determined or not bounded, an
error between :data:`fricid.metrics.NOISE_RATIO` and :data:`MISS_RATIO` times the scatter,
no held-out error or no scatter, convergence not recorded, set-points flagged for scatter or
with outliers dropped, a gap between the measured speeds (held-out validation leaves out
measured levels and so says nothing of a gap), gravity possibly left in the friction
(:func:`._diagnostics.gravity_caveat`: the extraction says it did not remove it or that eq.
7 left a pattern along the position, or repeated runs differ far more than their own
``std / sqrt(count)`` explains)); ``"yes"`` otherwise. A model whose error
misses the scatter gets what to do (:func:`._advice.misfit_advice`).

Reuse. The model file may carry the record (``FittedModel.trust``; ``fricid fit`` and the
fleet store it). :func:`assess_trust` returns it instead of computing again only when it was
computed by this record format (:data:`TRUST_VERSION`) on the same samples (their values,
:func:`fricid.samples.samples_hash`, and what the scatter and the quality table read: count,
std, ``meta`` sem and quality), with the same options (``validate``, the work limits), for
the same model (every field of the file but ``trust`` and the provenance's source, time,
version and warnings); anything else is computed again. A record that does not parse is ignored.

Shared error. Samples from an arm's sweeps (:func:`fricid.extract.extract_arm`) carry one error
of the identified gravity (:mod:`fricid.identify.static.shared_error`) that no fit removes: a
law fitted on some of them carries it into its predictions of the others, apart from the part
its offsets absorb (:func:`._heldout.shared_mse`, ``Trust.shared_rms``). It never makes an
error pass: the grade stays against the measurement scatter. Where the error misses that
scatter but not the scatter and the shared error together (in quadrature, by
:data:`MISS_RATIO`), the verdict is "with caveats", saying the samples cannot tell the law's
misfit from the shared error, not "no" (a per-direction offset of the gravity looks like an
asymmetric Coulomb level: with the gravity parameters poorly told by the sweeps, a symmetric
law and the per-direction one fit equally well). Where that error is larger than the
scatter, an error within the scatter is not a "yes" either: a misfit of its size would not
show. Counting it in the scatter instead passed a wrong symmetric law as "yes" (0.10x) on a
sweep whose gravity the sweeps hardly told (the realised error had cancelled the truth's
asymmetry: 0.77x the measurement scatter alone).

This module is longer than 500 lines because the record, its reuse and the grading rules are
one verdict, computed in one place.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields
from typing import Any

import numpy as np

from ..fitted import FittedModel
from ..fitted._file import _convergence_line
from ..metrics import NOISE_RATIO, verdict
from ..samples import FrictionSamples
from ._diagnostics import (
    DROPS,
    channel_problems,
    downweighted,
    gravity_caveat,
    listed_count,
    not_determined,
    open_sides,
    quality_rows,
    range_text,
    recorded_caveats,
)
from ._fingerprint import canonical, check_record_types, json_ready, record_key, trust_options
from ._heldout import (
    LEARNED_VALIDATE_WORK,
    LOVO_INTERIOR,
    MIN_LEVELS,
    NEW_SAMPLES,
    TINY_SAMPLES,
    VALIDATE_WORK,
    end_levels,
    grade_new_samples,
    graded_rmse,
    is_new_samples,
    model_error,
    on_new_clause,
    other_side_caveat,
    own_cv,
    own_directions,
    run_validation,
    shared_mse,
    worse_kfold,
)
from ._scatter import SECOND_DIFFERENCES, STD_OVER_ROOT_COUNT

__all__ = [
    "DROPS",
    "ESTIMATED",
    "FROM_FIT",
    "HELD_OUT",
    "IN_SAMPLE",
    "KFOLD_HERE",
    "LEARNED_VALIDATE_WORK",
    "LOVO_INTERIOR",
    "MIN_LEVELS",
    "MISS_RATIO",
    "NEW_SAMPLES",
    "OWN_CV",
    "RUN_HERE",
    "SECOND_LOG",
    "TINY_SAMPLES",
    "TRUST_VERSION",
    "VALIDATE_WORK",
    "Trust",
    "assess_trust",
    "not_determined",
    "open_sides",
    "own_cv",
    "range_text",
    "trust_options",
]

#: A model whose (held-out) RMSE exceeds this multiple of the measurement scatter is not
#: trusted: most of its error is the model's, not the noise's.
MISS_RATIO = 3.0

#: Format of the record and of the rules behind it: a stored record of another is recomputed.
TRUST_VERSION = 6

#: ``Trust.heldout_source``: leave-one-velocity-out run by :func:`assess_trust`.
RUN_HERE = "lovo run here"
#: ... random folds run by :func:`assess_trust` on tiny data, the worse of them and lovo.
KFOLD_HERE = "random folds run here"
#: ... the fit's own held-out validation (``--validate``, the manifest's ``validate``, auto).
FROM_FIT = "the fit's --validate"
#: ... a learned model's own structure-search cross-validation.
OWN_CV = "the learned model's own CV"
#: ... no held-out error: the fit's in-sample RMSE over the scatter.
IN_SAMPLE = "in-sample only"
#: Said in the reasons when the scatter is estimated (:func:`._scatter.second_difference_scatter`).
ESTIMATED = "estimated from second differences: no repeated runs, so not measured"
#: ... when it is the samples' std / sqrt(count) (their autocorrelation-aware errors missing).
LOWER_BOUND = "std/sqrt(count), a lower bound (it ignores the raw samples' autocorrelation)"
SECOND_LOG = "a second log"  #: ... run along by :func:`.trajectory_check.heldout_grading`
#: The sources whose ratio is a held-out one.
HELD_OUT = (RUN_HERE, FROM_FIT, OWN_CV, KFOLD_HERE, SECOND_LOG, NEW_SAMPLES)


@dataclass
class Trust:
    """Whether to trust a model, the diagnostics behind it, and where each number came from.

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
        RMSE over the measurement scatter: held out when ``heldout_source`` is one of
        :data:`HELD_OUT`, else the fit's in-sample ratio (NaN when there is no scatter).
    heldout_rmse, scatter : float
        N m, the RMSE of that ratio and the scatter (NaN when unknown).
    scatter_method : str
        How the scatter was estimated (``Scatter.method``; ``""`` when not recorded): one
        estimated from second differences (no repeats) is said so in the reasons.
    heldout_source : str
        :data:`RUN_HERE`, :data:`FROM_FIT`, :data:`OWN_CV`, :data:`IN_SAMPLE`, or ``""``
        (no ratio at all).
    heldout_scheme : str
        The scheme (``"lovo"``, ``"kfold:5"``, ``"levels:4"``, a second log's scope; ``""``: none).
    verdict : str
        :func:`fricid.metrics.verdict` of the ratio.
    validation : dict or None
        The validation the ratio is on (``Validation.to_dict()``), None in-sample.
    validation_note : str
        How a validation was run here, or why none was.
    range : str
        The extrapolation-free operating range, as text.
    quality : list of dict or None
        The samples' ``meta["quality"]`` rows, None when not recorded.
    quality_summary : str
        One line on them.
    learned : bool
        The model is learned (the RBF network, the hybrid, the GP: no physical parameters
        to identify).
    cv : dict or None
        A learned model's own cross-validation record when the verdict is on another
        validation (shown beside it).
    what_to_do : str
        For a model whose error misses the scatter: what to do; "" otherwise.
    downweighted : list of str
        The samples a robust fit down-weighted (:func:`._diagnostics.downweighted`), left out
        of the error graded (the fit is judged on the inliers).
    model : str
        The model's registry name.
    samples_hash, samples_detail_hash, model_hash : str or None
        What it was computed on (module notes, "Reuse"); None without samples.
    options : dict
        The options it was computed with (:func:`trust_options`).
    version : int
        :data:`TRUST_VERSION` of the record.
    reused : bool
        Read from the model file rather than computed now (not stored).
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
    scatter_method: str = ""
    shared_rms: float = float("nan")
    heldout_source: str = ""
    heldout_scheme: str = ""
    verdict: str = ""
    validation: dict[str, Any] | None = None
    validation_note: str = ""
    range: str = ""
    quality: list[dict[str, Any]] | None = None
    quality_summary: str = ""
    learned: bool = False
    cv: dict[str, Any] | None = None
    what_to_do: str = ""
    downweighted: list[str] = field(default_factory=list)
    model: str = ""
    samples_hash: str | None = None
    samples_detail_hash: str | None = None
    model_hash: str | None = None
    options: dict[str, Any] = field(default_factory=dict)
    version: int = TRUST_VERSION
    reused: bool = field(default=False, compare=False)

    @property
    def held_out(self) -> bool:
        """The ratio is a held-out one (:data:`HELD_OUT`)."""
        return self.heldout_source in HELD_OUT

    def line(self) -> str:
        """``"Trust: with caveats, because ..."``, and for a model that misses the data what
        to do."""
        out = f"Trust: {self.level}, because " + "; ".join(self.reasons) + "."
        return out + (f" What to do: {self.what_to_do}." if self.what_to_do else "")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (non-finite numbers as None), for the model file's ``trust``."""
        d = asdict(self)
        d.pop("reused")
        return json_ready(d)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Trust:
        """The record :meth:`to_dict` wrote (unknown keys ignored).

        Raises
        ------
        TypeError, ValueError, KeyError
            Not such a record.
        """
        known = {f.name for f in fields(cls)} - {"reused"}
        kwargs = {k: v for k, v in dict(d).items() if k in known}
        for key in ("heldout_ratio", "heldout_rmse", "scatter", "shared_rms"):
            value = kwargs.get(key)
            if value is not None and (
                isinstance(value, bool) or not isinstance(value, int | float)
            ):
                raise TypeError(f"trust record: '{key}' is not a number")
            kwargs[key] = float("nan") if value is None else float(value)
        out = cls(**kwargs)
        check_record_types(out)
        return out


# -- what a record was computed on -------------------------------------------------------


def _stored(fitted: FittedModel, key: dict[str, Any]) -> Trust | None:
    """The model file's record when it was computed on ``key`` (module notes), else None."""
    if not isinstance(fitted.trust, dict):
        return None
    try:
        stored = Trust.from_dict(fitted.trust)
    except (TypeError, ValueError, KeyError):
        return None
    same = all(canonical(getattr(stored, k)) == canonical(v) for k, v in key.items())
    if not same:
        return None
    stored.reused = True
    return stored


# -- the verdict --------------------------------------------------------------------------


def assess_trust(
    fitted: FittedModel,
    samples: FrictionSamples | None = None,
    *,
    validate: bool = True,
    max_work: int = VALIDATE_WORK,
    reuse: bool = True,
) -> Trust:
    """Whether to trust ``fitted``, from its file and (optionally) its samples.

    Parameters
    ----------
    fitted : FittedModel
        The model.
    samples : FrictionSamples, optional
        The samples it was identified on: their quality table, and the held-out validation
        when the fit has none. Others (a content hash other than the file's
        ``provenance["samples_sha256_16"]``): the model's own error on them is graded
        (:data:`NEW_SAMPLES`), not a refit.
    validate : bool, default True
        Run :func:`fricid.identify.validate` (``lovo``) when the fit holds no validation, or
        only a learned model's own cross-validation, and the problem is small enough (module
        notes).
    max_work : int
        The size limit of an analytic model's validation (:data:`VALIDATE_WORK`).
    reuse : bool, default True
        Return the record the model file carries when it was computed on the same samples,
        options and model (module notes, "Reuse").

    Returns
    -------
    Trust
        The level and its reasons, each number with its source (module notes).
    """
    options = trust_options(validate, max_work)
    samples, others = own_directions(fitted, samples)
    key = record_key(fitted, samples, options, TRUST_VERSION)
    if reuse:
        stored = _stored(fitted, key)
        if stored is not None:
            return stored
    trust = _base(fitted, samples)
    trust.samples_hash, trust.samples_detail_hash = key["samples_hash"], key["samples_detail_hash"]
    trust.model_hash, trust.options = key["model_hash"], options
    if is_new_samples(fitted, samples, trust.samples_hash):
        outside = grade_new_samples(trust, fitted, samples)
        trust.quality, trust.quality_summary, quality_caveat = quality_rows(samples)
        problems = channel_problems(samples)
        _grade(trust, fitted, [outside, quality_caveat, *gravity_caveat(samples)], problems)
        if trust.heldout_ratio > MISS_RATIO and not problems:
            trust.what_to_do = (
                "check that these samples come from the same joint, in the same units; if the "
                "joint has changed (wear, temperature, load), identify it again on them "
                f"(fricid fit SAMPLES --model {fitted.model})"
            )
        return trust
    mine = own_cv(fitted.validation)
    can_run = samples is not None and validate and trust.converged
    low, trust.downweighted = downweighted(fitted, samples)
    judged = samples if low is None else samples.subset(~low)  # a robust fit: its inliers
    if (mine or fitted.validation is None or low is not None) and can_run:
        val, trust.validation_note = run_validation(fitted, judged, max_work)
        if val is not None:
            trust.validation, trust.heldout_source = val, RUN_HERE
    elif fitted.validation is None:
        trust.validation_note = "no held-out validation in the file; in-sample only"
    elif mine:
        trust.validation_note = "leave-one-velocity-out not run here; the fit's own CV only"
    if trust.validation is None and fitted.validation is not None and low is None:
        trust.validation = fitted.validation
        trust.heldout_source = OWN_CV if mine else FROM_FIT
    if mine and trust.heldout_source == RUN_HERE:
        trust.cv = fitted.validation
    _ratio(trust, fitted, judged, inliers=low is not None)
    random = trust.heldout_scheme.startswith("kfold")
    if can_run and len(judged) <= TINY_SAMPLES and not random:  # the worse of the two
        before = trust.heldout_ratio if trust.held_out else np.nan
        val, note = worse_kfold(fitted, judged, max_work, before, trust.heldout_scheme)
        trust.validation_note = "; ".join(x for x in (trust.validation_note, note) if x)
        if val is not None:
            trust.validation, trust.heldout_source = val, KFOLD_HERE
            _ratio(trust, fitted, judged, inliers=low is not None)
    if low is not None:
        loss = (fitted.loss or {}).get("loss")
        how = f"the {loss} loss down-weighted" if loss else "the training took as gross errors"
        trust.validation_note = (
            f"judged on the {len(judged)} inliers, the {int(low.sum())} sample(s) {how} "
            "left out; " + trust.validation_note
        )
    trust.quality, trust.quality_summary, quality_caveat = quality_rows(samples)
    problems = channel_problems(samples)
    side = other_side_caveat(fitted, others, trust.scatter)
    _grade(trust, fitted, [side, quality_caveat, *gravity_caveat(samples)], problems)
    if trust.converged is not False and trust.heldout_ratio > MISS_RATIO and not problems:
        from ._advice import misfit_advice

        held = trust.validation if trust.held_out else None
        trust.what_to_do = misfit_advice(fitted, held, trust.scatter, MISS_RATIO, judged)
    return trust


def _base(fitted: FittedModel, samples: FrictionSamples | None) -> Trust:
    """The record's file diagnostics: convergence, identifiability, range (module notes)."""
    conv = fitted.convergence
    converged = fitted.converged
    if conv is None:
        line = "not recorded in this model file"
    elif converged:
        line = _convergence_line(conv)
    else:
        line = f"NOT converged: {conv.get('reason') or conv.get('message') or 'no reason given'}"
    return Trust(
        level="yes",
        reasons=[],
        converged=converged,
        convergence=line,
        advice=str(conv.get("advice", "")) if conv is not None and not converged else "",
        not_determined=not_determined(fitted),
        open_sides=open_sides(fitted),
        range=range_text(fitted),
        learned=fitted.kind == "rbf",
        model=fitted.model,
    )


def _ratio(
    trust: Trust, fitted: FittedModel, samples: FrictionSamples | None, inliers: bool = False
) -> None:
    """The ratio to grade by: held out (``trust.validation``; leave-one-velocity-out on its
    interior folds, :func:`._heldout.graded_rmse`), else the file's in-sample ratio, else the
    in-sample ratio on ``samples`` (a network's file may not record its scatter, and the
    file's ratio holds a robust fit's outliers: ``inliers``, ``samples`` are its inliers)."""
    v = trust.validation
    if v and v.get("ratio") is not None:
        trust.heldout_rmse, trust.heldout_scheme = graded_rmse(v)
        trust.scatter = float(v["scatter"]) if v.get("scatter") is not None else np.nan
        trust.heldout_ratio = trust.heldout_rmse / trust.scatter
        trust.scatter_method = str(v.get("scatter_method") or "")
    else:  # no held-out ratio (no validation, or one without a scatter): in-sample
        trust.heldout_source = ""
        if fitted.metrics.get("rmse_over_scatter") is not None and not inliers:
            trust.heldout_ratio = float(fitted.metrics["rmse_over_scatter"])
            trust.heldout_rmse = float(fitted.metrics.get("rmse", np.nan))
            trust.scatter = float(fitted.metrics.get("scatter", np.nan))
            trust.heldout_source = IN_SAMPLE
            recorded = (fitted.loss or {}).get("scatter") or {}
            trust.scatter_method = str(recorded.get("method") or "")
        elif samples is not None and model_error(trust, fitted, samples):
            trust.heldout_source = IN_SAMPLE
    shared = (
        0.0 if trust.not_determined else shared_mse(fitted, samples, v if trust.held_out else None)
    )
    if shared > 0 and np.isfinite(trust.scatter) and trust.scatter > 0:  # "Shared error"
        trust.shared_rms = float(np.sqrt(shared))
    trust.verdict = verdict(trust.heldout_ratio)


def _shared_reading(trust: Trust) -> str:
    """What the error every sample shares says of an error that misses the scatter (module
    notes, "Shared error"): ``""`` when there is none, or the miss stands without it; else the
    clause saying the samples cannot tell the law's misfit from it."""
    ratio, shared = trust.heldout_ratio, trust.shared_rms
    if not (np.isfinite(ratio) and np.isfinite(shared) and ratio > NOISE_RATIO):
        return ""
    total = trust.heldout_rmse / float(np.hypot(trust.scatter, shared))
    advice = (
        f" ({shared:.3g} N m RMS of the arm's identified gravity, which no fit removes): these "
        "samples cannot tell a misfit of this law from it (sweep the other joints at more "
        "poses, or keep the URDF's masses: fricid robot extract --urdf-masses)"
    )
    if total <= NOISE_RATIO:
        return ", within what an error every sample shares explains" + advice
    if ratio > MISS_RATIO >= total:
        return f", {total:.3g}x with an error every sample shares counted" + advice
    return ""


def _grade(trust: Trust, fitted: FittedModel, sample_caveats: list[str], no: list[str]) -> None:
    """Set ``trust.level`` and ``trust.reasons`` (module notes); ``no``: reasons for "no"."""
    no, caveats = list(no), []
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
    kind = "held-out" if trust.held_out else "in-sample"
    if trust.heldout_source == NEW_SAMPLES:
        kind = "model's"
    shared = _shared_reading(trust)
    if np.isfinite(ratio) and ratio > MISS_RATIO and not shared:
        no.append(f"the {kind} error {trust.verdict} the measurement scatter{on_new_clause(trust)}")
    elif np.isfinite(ratio) and ratio > NOISE_RATIO:
        new = on_new_clause(trust)
        caveats.append(f"the {kind} error {trust.verdict} the measurement scatter{new}{shared}")
    elif not np.isfinite(ratio):
        caveats.append("no measurement scatter to compare the error with")
    if not shared and np.isfinite(ratio) and trust.shared_rms > trust.scatter:
        caveats.append(
            f"the samples share an error larger than their scatter ({trust.shared_rms:.3g} N m "
            f"RMS in this law's errors against {trust.scatter:.3g} N m: the arm's identified "
            "gravity): a misfit of that size would not show (sweep the other joints at more "
            "poses, or keep the URDF's masses: fricid robot extract --urdf-masses)"
        )
    if np.isfinite(ratio) and not trust.held_out and not no:
        caveats.append("no held-out validation (in-sample error only)")
    elif np.isfinite(ratio) and trust.heldout_source == OWN_CV and not no:
        levels = trust.heldout_scheme.startswith("levels")
        caveats.append(
            "held out between the measured speeds only (the fit's own CV over whole speed "
            "levels; beyond them untested)"
            if levels
            else "held out at the measured velocity levels only (the fit's own random-fold CV; "
            "between and beyond them untested)"
        )
    caveats += [c for c in sample_caveats if c]
    caveats += recorded_caveats(fitted)
    if trust.downweighted:
        loss = (fitted.loss or {}).get("loss")
        how = f"the {loss} loss down-weighted" if loss else "the training left out"
        caveats.append(
            f"{how} {listed_count(trust.downweighted)} sample(s) as outliers "
            f"({'; '.join(trust.downweighted)}), left out of the error graded"
        )
    estimated = trust.scatter_method == SECOND_DIFFERENCES and np.isfinite(ratio)
    said = [f"the scatter is {ESTIMATED}"] if estimated else []
    if trust.scatter_method == STD_OVER_ROOT_COUNT and np.isfinite(ratio):
        said.append(f"the scatter is {LOWER_BOUND}")
    if no:
        trust.level, trust.reasons = "no", no + caveats + said
        return
    if caveats:
        trust.level, trust.reasons = "with caveats", caveats + said
        return
    which = f"the scatter {ESTIMATED}" if estimated else "the scatter"
    if trust.scatter_method == STD_OVER_ROOT_COUNT:
        which = f"the scatter, {LOWER_BOUND}"
    scheme = str(trust.heldout_scheme or "")
    ends = end_levels(trust.validation, trust.scatter) if scheme == LOVO_INTERIOR else ""
    if trust.held_out and scheme.startswith("kfold"):  # not the lovo figure printed beside it
        ends = f" in random folds, {scheme}"
    held = f"{kind} error is within noise ({ratio:.2f}x {which}{ends}){on_new_clause(trust)}"
    det = "every parameter is determined" if free else "the network fits"
    trust.level, trust.reasons = "yes", [f"the fit converged, {det} and the {held}"]
