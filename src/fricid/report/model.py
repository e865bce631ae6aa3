"""The report for one identified model on one data set (``fricid report MODEL.json SAMPLES``).

Contents, in order: "Can I trust this?" first (:mod:`.trust` renders the record
:func:`fricid.identify.trust.assess_trust` computed: a one-line verdict, data quality per
set-point, convergence, identifiability, held-out error against the measurement scatter and
where it came from, operating range); the model and its parameters with their 95 % intervals
``[low, high]`` (profile likelihood inside the search box where the model file has them, open
sides marked; for the RBF network, predicted friction with bootstrap intervals over the
operating range, its weights in an appendix); fit metrics on the identification data and on the
given samples, measured against predicted friction over velocity (one curve per temperature and
load band), the Stribeck region and the 95 % prediction interval against speed on a log axis,
residuals against each input, predicted against measured, and the optimiser's convergence
history where there is one.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

import numpy as np
import pandas as pd

from ..fitted import FittedModel, Parameter
from ..identify import evaluate, unit_mismatches
from ..identify.trust import Trust, not_determined
from ..metrics import rmspe_note
from ..samples import FrictionSamples
from . import interactive, plots
from .band import held_at, prediction_band_figure
from .document import Document, Figure, Note, Table
from .trust import quality_frame, scatter_explanation, trust_text

__all__ = ["METRIC_LABELS", "metrics_table", "model_report", "parameter_table"]

logger = logging.getLogger(__name__)

#: Display name of each metric of :func:`fricid.metrics.metrics`, with its unit.
METRIC_LABELS: dict[str, str] = {
    "n": "samples",
    "fitness": "fitness R²",
    "sse": "SSE [N² m²]",
    "rmse": "RMSE [N m]",
    "rmspe": "RMSPE [%]",
    "mae": "mean |error| [N m]",
    "max_abs_error": "max |error| [N m]",
}


def _metric_value(key: str, value: float) -> float:
    return 100.0 * value if key == "rmspe" else value


def _interval(fitted: FittedModel, p: Parameter) -> tuple[float, float, str, str]:
    """(low, high, text, method) of a free parameter's 95 % interval; NaNs and "" for none."""
    low, high = p.ci95
    method = fitted.ci_method or "jacobian"
    if not p.has_interval:
        half = p.ci95_halfwidth
        if not np.isfinite(half) or fitted.converged is False:
            return np.nan, np.nan, "", ""
        low, high, method = p.value - half, p.value + half, "jacobian (value ± half-width)"
    lo_t = f"{low:.4g}" + (" (open)" if p.low_open else "")
    hi_t = f"{high:.4g}" + (" (open)" if p.high_open else "")
    return low, high, f"[{lo_t}, {hi_t}]", method


def parameter_table(fitted: FittedModel) -> pd.DataFrame:
    """One row per parameter: value, unit, the 95 % interval ``[low, high]`` (profile
    likelihood where the file has it; a side that reaches the search bound marked "(open)"),
    how it was found, and the status (fixed, not determined, no interval and why, at a bound,
    not bounded by the data, free)."""
    rows = []
    undetermined = set(not_determined(fitted))
    for name, p in fitted.parameters.items():
        if p.fixed:
            low, high, text, method, status = np.nan, np.nan, "", "", "fixed"
        else:
            low, high, text, method = _interval(fitted, p)
            if name in undetermined:
                status = p.note or "not determined (Jacobian rank-deficient)"
            elif fitted.converged is False:
                status = "no interval: the fit did not converge"
            elif p.note:
                status = p.note
            elif p.at_bound:
                status = "at a bound of the search box"
            elif not text:
                status = "no interval"
            else:
                status = "free"
        rows.append(
            {
                "parameter": name,
                "value": p.value,
                "unit": p.unit,
                "95% interval": text or "–",
                "95% CI low": low,
                "95% CI high": high,
                "interval method": method or "–",
                "status": status,
            }
        )
    return pd.DataFrame(rows)


def metrics_table(
    fitted: FittedModel, on_samples: dict[str, float] | None, samples_label: str = "these samples"
) -> pd.DataFrame:
    """Fit metrics on the identification data (from the model file) and on ``on_samples``."""
    rows = []
    for key, label in METRIC_LABELS.items():
        row = {"metric": label, "identification data": np.nan}
        if key in fitted.metrics:
            row["identification data"] = _metric_value(key, fitted.metrics[key])
        if on_samples is not None:
            row[samples_label] = _metric_value(key, on_samples.get(key, np.nan))
        rows.append(row)
    return pd.DataFrame(rows)


def _range_note(fitted: FittedModel, samples: FrictionSamples) -> Note | None:
    outside = []
    for name, col in (
        ("velocity", samples.velocity),
        ("load", samples.load),
        ("temperature", samples.temperature),
    ):
        rng = fitted.operating_range.get(name)
        if not rng:
            continue
        lo, hi = rng
        tol = 1e-9 * max(abs(lo), abs(hi), 1.0)
        n = int(np.sum((col < lo - tol) | (col > hi + tol)))
        if n:
            outside.append(
                f"{n} samples have {name} outside the identified range [{lo:.4g}, {hi:.4g}]"
            )
    if not outside:
        return None
    return Note(
        "Extrapolation: " + "; ".join(outside) + ". Predictions there are not backed "
        "by identification data.",
        kind="warning",
    )


def _correlation_frame(fitted: FittedModel) -> pd.DataFrame | None:
    if not fitted.correlation:
        return None
    free = list(fitted.free)
    corr = np.asarray(fitted.correlation, dtype=float)
    if corr.shape != (len(free), len(free)):
        return None
    return pd.DataFrame(corr, index=pd.Index(free, name="parameter"), columns=free)


def _strong_correlations(frame: pd.DataFrame, limit: float = 0.9) -> list[str]:
    names = list(frame.columns)
    out = []
    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            c = frame.iat[i, j]
            if np.isfinite(c) and abs(c) >= limit:
                out.append(f"{names[i]}–{names[j]} ({c:+.3f})")
    return out


def _model_description(fitted: FittedModel) -> str:
    if fitted.model in ("gp", "hybrid"):
        from ..models import get_predictor

        return get_predictor(fitted.model).describe(fitted.state) + "."
    if fitted.kind == "rbf":
        *first, last = fitted.inputs_used()
        of = f"{', '.join(first)} and {last}" if first else last
        return (
            "RBF neural network (BAS-RBFNN paper, eq. 14-15): Gaussian basis functions of "
            f"{of}, linear output layer."
        )
    m = fitted.friction_model()
    return f"{m.title} ({m.equation}); parameters {', '.join(m.param_names)}."


def model_report(
    fitted: FittedModel,
    samples: FrictionSamples,
    *,
    trust: Trust,
    velocity_unit: str = "rad/s",
    samples_label: str | None = None,
    bootstrap: int = 200,
    seed: int = 0,
    progress: Callable[[str], Any] | None = None,
) -> Document:
    """Build the report of ``fitted`` on ``samples``.

    The order is what a reader wants first: the trust verdict, the figures (friction
    against velocity, residuals), then the parameters and the metrics; tables longer than
    :data:`fricid.report.document.FOLD_ROWS` rows (the data quality per set-point, the
    held-out folds) are folded in the HTML.

    Parameters
    ----------
    fitted : the identified model (``FittedModel.load`` of a JSON model file).
    samples : friction samples to compare against (usually the identification data).
    trust : the trust record to show first (:func:`fricid.identify.trust.assess_trust` of
        ``fitted`` and ``samples``; the report renders it and computes no verdict).
    velocity_unit : display unit of velocity in the figures (``rad/s``, ``deg/s``, ``rpm``).
    samples_label : name of the samples in tables (default: their source file name).
    bootstrap : resamples for the RBF network's prediction interval (ignored for analytic
        models, whose CIs come from the Jacobian at the optimum).
    seed : seed of the bootstrap.
    progress : called with the part being built (``"figures: friction against velocity"``,
        ...), for a command's progress display.

    Returns
    -------
    Document, to be written with :func:`fricid.report.write_document`.
    """
    say = progress or (lambda _label: None)
    say("predictions, metrics")
    label = samples_label or (
        str(samples.source).rsplit("/", 1)[-1] if samples.source else "these samples"
    )
    opt = fitted.optimizer
    predicted = fitted.predict(samples.X)
    residual = samples.friction - predicted
    on_samples = evaluate(fitted, samples)
    doc = Document(
        title=f"Friction model report: {fitted.model}",
        summary=_model_description(fitted),
        meta={
            "model": fitted.model,
            "identified by": f"{opt.method} (seed {opt.seed}, {opt.nfev} evaluations)"
            if opt.method
            else "–",
            "identification data": fitted.provenance.get("source") or "–",
            "samples in this report": f"{label} ({len(samples)} rows, directions "
            f"{', '.join(str(d) for d in samples.directions())})",
            "fitness R² on these samples": on_samples["fitness"],
            "RMSE on these samples [N m]": on_samples["rmse"],
            "created by fricid": fitted.provenance.get("fricid_version", "–"),
        },
    )

    record = (
        "read from the model file (computed on these samples with these options)"
        if trust.reused
        else "computed for this report"
    )
    units = unit_mismatches(fitted, samples)  # beside the verdict: every error compares two
    warn = {what: f"warning: {why}." for what, why in units.items()}
    doc.meta = {"trust": trust.line(), "trust record": record, **warn, **doc.meta}
    _trust_section(doc, trust)

    appendix: list = []
    say("figures: friction against velocity")
    sec = doc.section("Friction against velocity")
    sec.add(
        Figure(
            "friction_vs_velocity",
            "Measured and predicted friction against velocity",
            plots.friction_curves(
                samples,
                fitted.predict,
                velocity_unit=velocity_unit,
                title=f"{fitted.model}: friction against velocity",
            ),
            caption=_curves_caption(samples, fitted.inputs_used()),
            plotly=interactive.friction_figure(
                samples,
                fitted.predict,
                velocity_unit=velocity_unit,
                title=f"{fitted.model}: friction against velocity",
            ),
        )
    )
    if (samples.velocity != 0).any():
        marks = interactive.stribeck_velocities(fitted.params)
        moving = samples.subset(samples.velocity != 0)
        sec.add(
            Figure(
                "stribeck_region",
                "The Stribeck region: friction magnitude against speed, log axis",
                plots.stribeck_region(
                    moving,
                    fitted.predict,
                    marks,
                    velocity_unit=velocity_unit,
                    xlim=interactive.stribeck_range(moving.velocity, marks),
                ),
                caption="The low-speed end, where friction falls from its static level to the "
                "Coulomb level, on a log speed axis, per direction (up to 20 times the "
                "Stribeck velocity where that is inside the data; the interactive figure "
                "zooms out on a double click)"
                + (
                    "; dotted lines mark the model's Stribeck velocities ("
                    + ", ".join(marks)
                    + ")."
                    if marks
                    else "."
                ),
                plotly=interactive.stribeck_figure(
                    moving, fitted.predict, fitted.params, velocity_unit=velocity_unit
                ),
            )
        )
        band = prediction_band_figure(fitted, moving, velocity_unit)
        if band is not None:
            sec.add(band)
    sec.add(
        Figure(
            "parity",
            "Predicted against measured friction",
            plots.parity(samples.friction, predicted, title=f"{fitted.model}"),
            caption="Points on the grey identity line are predicted exactly.",
        )
    )

    say("figures: residuals against each input")
    sec = doc.section("Residuals")
    sec.add(
        Figure(
            "residuals",
            "Residuals against each input",
            plots.residual_panels(samples, residual, velocity_unit=velocity_unit),
            caption="Measured minus predicted friction against each input that varies "
            "in the data; structure (a trend, a curve) means the model misses an "
            "effect, scatter within the dashed ±2 RMSE lines is noise.",
            plotly=interactive.residual_figure(samples, residual, velocity_unit=velocity_unit),
        )
    )

    say("parameters" + (", bootstrap intervals" if fitted.kind == "rbf" else ""))
    sec = doc.section("Parameters", _param_text(fitted))
    if fitted.model == "gp":  # the Gaussian process: its posterior band at the samples
        mean, std = fitted.predict(samples.X, warn=False, return_std=True)
        band = {
            "predicted [N m]": mean,
            "95% low": mean - 1.96 * std,
            "95% high": mean + 1.96 * std,
        }
        frame = pd.DataFrame({"velocity [rad/s]": samples.velocity, **band})
        sec.add(
            Table(
                "prediction_band",
                "Predicted friction with the GP's 95 % band",
                frame,
                caption="Posterior of the latent friction (without the white noise).",
            )
        )
    elif fitted.kind == "rbf":
        from .rbf import rbf_parameter_items

        main, appendix = rbf_parameter_items(fitted, samples, n_boot=bootstrap, seed=seed)
        for item in main:
            sec.add(item)
    else:
        sec.add(
            Table(
                "parameters",
                "Identified parameters with 95 % intervals",
                parameter_table(fitted),
                caption=(
                    "95 % interval [low, high]: profile likelihood inside the search box "
                    "where the model file has it (the parameter's values whose re-fitted SSE "
                    "stays within the F-test threshold), else the Jacobian's linearised "
                    "interval; a side marked (open) reaches the search bound: the data do "
                    "not bound the parameter there. A fit that did not converge has none."
                ),
            )
        )
        corr = _correlation_frame(fitted)
        if corr is not None:
            strong = _strong_correlations(corr)
            sec.add(
                Table(
                    "correlation",
                    "Correlation of the free parameters",
                    corr,
                    index=True,
                    digits=3,
                    caption=(
                        "Strongly correlated pairs (|r| ≥ 0.9), poorly separable by "
                        "these data: " + ", ".join(strong) + "."
                    )
                    if strong
                    else "No pair of parameters is correlated beyond |r| = 0.9.",
                )
            )

    sec = doc.section("Fit quality")
    sec.add(
        Table(
            "metrics",
            "Fit metrics",
            metrics_table(fitted, on_samples, label),
            caption="Fitness is R² = 1 − SSE/SST (BAS-RBFNN paper Table 1); RMSPE is the "
            "root mean square relative error; mean and max |error| are the BAS-RBFNN "
            "paper's Table 3 measures.",
        )
    )
    for why in units.values():
        sec.add(Note(f"The errors on {label} do not measure the model: {why}.", "warning"))
    said = rmspe_note(samples.y, fitted.predict(samples.X, warn=False))
    if said:
        sec.add(Note(f"{said}.", "text"))
    note = _range_note(fitted, samples)
    if note is not None:
        sec.add(note)

    if appendix:
        sec = doc.section("Appendix: the network's output weights")
        for item in appendix:
            sec.add(item)

    history = np.asarray(opt.history, dtype=float) if opt.history else None
    if history is not None and history.ndim == 2 and len(history) > 1:
        sec = doc.section("Convergence")
        sec.add(
            Figure(
                "convergence",
                "Optimiser convergence",
                plots.convergence(
                    {opt.method or "optimiser": history},
                    title=f"{opt.method}: best SSE against evaluations",
                ),
                caption="Best sum of squared errors found so far against the number of "
                "model evaluations (the RWSAVSBAS paper's fitness, eq. 11).",
            )
        )
    return doc


def _trust_section(doc: Document, trust: Trust) -> None:
    """The "Can I trust this?" section (first): the diagnostics behind the verdict, which
    the document's first row states (once: a note here repeated it word for word)."""
    sec = doc.section("Can I trust this?", trust_text(trust))
    if trust.quality:
        sec.add(
            Table(
                "quality",
                "Data quality per set-point",
                quality_frame(trust.quality),
                caption="Samples averaged into each set-point's friction and those dropped, "
                "by reason. " + scatter_explanation(trust) + " HIGH marks a set-point whose "
                "readings scatter far more than its neighbours'.",
            )
        )
    v = trust.validation
    if v and v.get("folds"):
        sec.add(
            Table(
                "heldout",
                f"Held-out error per fold ({v.get('scheme', '')})",
                pd.DataFrame(
                    {
                        "fold": [f["fold"] for f in v["folds"]],
                        "speed [rad/s]": [f["speed"] for f in v["folds"]],
                        "samples": [f["n"] for f in v["folds"]],
                        "held-out RMSE [N m]": [f["rmse"] for f in v["folds"]],
                        "note": [f.get("note", "") for f in v["folds"]],
                    }
                ),
                caption="Each fold's samples predicted by the model fitted without them.",
            )
        )


def _param_text(fitted: FittedModel) -> str:
    bits = []
    if fitted.fixed:
        bits.append(f"Held fixed: {', '.join(fitted.fixed)}.")
    if fitted.at_bound:
        bits.append(
            f"Ended on a bound of the search box: {', '.join(fitted.at_bound)}; widen "
            "the bound (`fricid fit --bound`) if that is not physical."
        )
    return " ".join(bits)


def _curves_caption(samples: FrictionSamples, inputs: tuple[str, ...]) -> str:
    """The caption of the friction against velocity; ``inputs`` are the model's (a curve
    holds at the band's median only those of load and temperature that the model uses)."""
    held = held_at(inputs, "each band's")
    parts = [
        "Markers are the measured friction samples, lines the model"
        + (f" evaluated at {held}." if held else ".")
    ]
    if np.ptp(samples.temperature) > 0 or np.ptp(samples.load) > 0:
        parts.append(
            "The interactive chart has one panel per load and temperature band (named above "
            "it; the axes shared, so panels compare at a glance) and a colour per direction; "
            "in the PNG the panels are load bands and the colours temperature bands."
        )
    if set(samples.directions()) == {-1, 1}:
        parts.append("Both directions of motion are shown; friction is signed like velocity.")
    return " ".join(parts)
