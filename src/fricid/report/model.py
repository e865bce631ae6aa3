"""The report for one identified model on one data set (``fricid report MODEL.json SAMPLES``).

Contents: the model and its parameters with 95 % confidence intervals (from the Jacobian at the
optimum, :attr:`FittedModel.ci95`; for the RBF network a bootstrap of its predictions), fit
metrics on the identification data and on the given samples, measured against predicted
friction over velocity (one curve per temperature and load band), residuals against each
input, predicted against measured, and the optimiser's convergence history where there is one.
"""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd

from ..fitted import FittedModel
from ..identify import evaluate
from ..samples import FrictionSamples
from . import plots
from .document import Document, Figure, Note, Table

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


def parameter_table(fitted: FittedModel) -> pd.DataFrame:
    """One row per parameter: value, unit, standard error, 95 % CI bounds, relative half-width
    and status (free, fixed, at a bound, not identifiable)."""
    rows = []
    for name, value in fitted.params.items():
        se = fitted.stderr.get(name, np.nan)
        ci = fitted.ci95.get(name, np.nan)
        if name in fitted.fixed:
            status, se, ci = "fixed", np.nan, np.nan
        elif name in fitted.at_bound:
            status = "at a bound of the search box"
        elif not np.isfinite(ci):
            status = "no CI (Jacobian rank-deficient)"
        else:
            status = "free"
        rel = 100.0 * ci / abs(value) if np.isfinite(ci) and value != 0 else np.nan
        rows.append(
            {
                "parameter": name,
                "value": value,
                "unit": fitted.units.get(name, ""),
                "std. error": se,
                "95% CI low": value - ci if np.isfinite(ci) else np.nan,
                "95% CI high": value + ci if np.isfinite(ci) else np.nan,
                "± [% of value]": rel,
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
    free = [n for n in fitted.params if n not in fitted.fixed]
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
    if fitted.kind == "rbf":
        return (
            "RBF neural network (BAS-RBFNN paper, eq. 14-15): Gaussian basis functions of "
            "velocity, load and temperature, linear output layer."
        )
    m = fitted.friction_model()
    return f"{m.title} ({m.equation}); parameters {', '.join(m.param_names)}."


def model_report(
    fitted: FittedModel,
    samples: FrictionSamples,
    *,
    velocity_unit: str = "rad/s",
    samples_label: str | None = None,
    bootstrap: int = 200,
    seed: int = 0,
) -> Document:
    """Build the report of ``fitted`` on ``samples``.

    Parameters
    ----------
    fitted : the identified model (``FittedModel.load`` of a JSON model file).
    samples : friction samples to compare against (usually the identification data).
    velocity_unit : display unit of velocity in the figures (``rad/s``, ``deg/s``, ``rpm``).
    samples_label : name of the samples in tables (default: their source file name).
    bootstrap : resamples for the RBF network's prediction interval (ignored for analytic
        models, whose CIs come from the Jacobian at the optimum).
    seed : seed of the bootstrap.

    Returns
    -------
    Document, to be written with :func:`fricid.report.write_document`.
    """
    label = samples_label or (
        str(samples.source).rsplit("/", 1)[-1] if samples.source else "these samples"
    )
    predicted = fitted.predict(samples.X)
    residual = samples.friction - predicted
    on_samples = evaluate(fitted, samples)
    doc = Document(
        title=f"Friction model report: {fitted.model}",
        summary=_model_description(fitted),
        meta={
            "model": fitted.model,
            "identified by": f"{fitted.method} (seed {fitted.seed}, {fitted.nfev} evaluations)"
            if fitted.method
            else "–",
            "identification data": fitted.provenance.get("source") or "–",
            "samples in this report": f"{label} ({len(samples)} rows, directions "
            f"{', '.join(str(d) for d in samples.directions())})",
            "fitness R² on these samples": on_samples["fitness"],
            "RMSE on these samples [N m]": on_samples["rmse"],
            "created by fricid": fitted.provenance.get("fricid_version", "–"),
        },
    )

    sec = doc.section("Parameters", _param_text(fitted))
    if fitted.kind == "rbf":
        from .rbf import rbf_parameter_items

        for item in rbf_parameter_items(fitted, samples, n_boot=bootstrap, seed=seed):
            sec.add(item)
    else:
        sec.add(
            Table(
                "parameters",
                "Identified parameters with 95 % confidence intervals",
                parameter_table(fitted),
                caption=(
                    "95 % CI: value ± t(0.975, n − p) × standard error, from the "
                    "Jacobian at the optimum (cov = s² (JᵀJ)⁻¹, s² = SSE / (n − p)). "
                    "Parameters at a bound of the search box have no meaningful CI."
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
    note = _range_note(fitted, samples)
    if note is not None:
        sec.add(note)

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
            caption=_curves_caption(samples),
        )
    )
    sec.add(
        Figure(
            "parity",
            "Predicted against measured friction",
            plots.parity(samples.friction, predicted, title=f"{fitted.model}"),
            caption="Points on the grey identity line are predicted exactly.",
        )
    )

    sec = doc.section("Residuals")
    sec.add(
        Figure(
            "residuals",
            "Residuals against each input",
            plots.residual_panels(samples, residual, velocity_unit=velocity_unit),
            caption="Measured minus predicted friction against each input that varies "
            "in the data; structure (a trend, a curve) means the model misses an "
            "effect, scatter within the dashed ±2 RMSE lines is noise.",
        )
    )

    history = np.asarray(fitted.history, dtype=float) if fitted.history else None
    if history is not None and history.ndim == 2 and len(history) > 1:
        sec = doc.section("Convergence")
        sec.add(
            Figure(
                "convergence",
                "Optimiser convergence",
                plots.convergence(
                    {fitted.method or "optimiser": history},
                    title=f"{fitted.method}: best SSE against evaluations",
                ),
                caption="Best sum of squared errors found so far against the number of "
                "model evaluations (the RWSAVSBAS paper's fitness, eq. 11).",
            )
        )
    return doc


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


def _curves_caption(samples: FrictionSamples) -> str:
    parts = [
        "Markers are the measured friction samples, lines the model evaluated at each "
        "band's median load and temperature."
    ]
    if np.ptp(samples.temperature) > 0 or np.ptp(samples.load) > 0:
        parts.append("Colours are temperature bands, panels load bands.")
    if set(samples.directions()) == {-1, 1}:
        parts.append("Both directions of motion are shown; friction is signed like velocity.")
    return " ".join(parts)
