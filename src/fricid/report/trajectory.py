"""The report of a model identified from a trajectory, on its log (``fricid report MODEL.json
LOG [HELDOUT_LOG]``).

Renders what :func:`fricid.identify.trajectory_check.predict_trajectory` computed (the report
computes no prediction): the measured and predicted torque over time with the residual (raw,
and low-passed by the fit's own parallel filter, the residual the identification minimised);
the residuals against velocity; the hysteresis at the velocity reversals, friction against
velocity and against the position travelled since the reversal (pre-sliding); the same on a
held-out log when one is given; the parameters with their 95 % intervals, and the joint's
inertia and gravity.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pandas as pd

from ..fitted import FittedModel
from ..fitted._report import DIRECTIONS
from ..identify.trajectory_check import REVERSAL_SPEED, TrajectoryPrediction, heldout_grading
from .document import Document, Figure, Note, Table
from .model import parameter_table
from .style import COLORS, new_figure, png, styled, torque_scale

__all__ = ["output_error_note", "trajectory_report"]

#: Reversal windows drawn in a hysteresis figure (the first ones of the log, evenly spread).
MAX_LOOPS = 12

#: Rows of the metrics table: key of ``TrajectoryPrediction.metrics`` and its label.
METRICS = {
    "n": "sample periods",
    "rmse": "RMS torque error [N m]",
    "median_abs_error": "median |torque error| [N m]",
    "max_abs_error": "max |torque error| [N m]",
    "signal_rms": "RMS of the measured torque about its mean [N m]",
    "relative": "RMS error / RMS torque",
    "fitness": "fitness R²",
    "rmse_filtered": "RMS torque error (the equation's), low-passed at the fit's cut-off [N m]",
    "n_sliding": "sample periods sliding (those a regression fits)",
    "rmse_sliding": "RMS torque error where it slides [N m]",
}


def _torque_over_time(pred: TrajectoryPrediction, title: str) -> bytes:
    f, unit = torque_scale(pred.torque)
    with styled():
        fig, axes = new_figure(2, 1, width=9.0, height=5.6, sharex=True)
        ax = axes[0, 0]
        ax.plot(pred.time, pred.torque * f, lw=0.8, color=COLORS[0], label="measured")
        ax.plot(pred.time, pred.predicted * f, lw=0.8, color=COLORS[1], label="predicted")
        ax.set_ylabel(f"torque [{unit}]")
        ax.legend(loc="upper right")
        ax.set_title(title)
        ax = axes[1, 0]
        ax.plot(pred.time, pred.residual * f, lw=0.6, color="0.6", label="raw")
        if np.isfinite(pred.residual_filtered).any():
            ax.plot(
                pred.time,
                pred.residual_filtered * f,
                lw=1.0,
                color=COLORS[2],
                label=f"low-passed ({pred.cutoff:g} Hz, as the fit)",
            )
        ax.axhline(0, color="0.3", lw=0.8)
        ax.set_xlabel("time [s]")
        ax.set_ylabel(f"residual [{unit}]")
        ax.legend(loc="upper right")
        return png(fig)


def _residual_vs_velocity(pred: TrajectoryPrediction, title: str) -> bytes:
    f, unit = torque_scale(pred.residual)
    with styled():
        fig, axes = new_figure(width=7.0, height=4.0)
        ax = axes[0, 0]
        ax.scatter(pred.velocity, pred.residual * f, s=3, alpha=0.3, color="0.5", label="raw")
        if np.isfinite(pred.residual_filtered).any():
            ax.scatter(
                pred.velocity,
                pred.residual_filtered * f,
                s=3,
                alpha=0.5,
                color=COLORS[2],
                label="low-passed",
            )
        ax.axhline(0, color="0.3", lw=0.8)
        ax.set_xlabel("velocity [rad/s]")
        ax.set_ylabel(f"residual [{unit}]")
        ax.legend(loc="best", markerscale=4)
        ax.set_title(title)
        return png(fig)


def _loops(pred: TrajectoryPrediction) -> list[np.ndarray]:
    windows = pred.reversals()
    if len(windows) <= MAX_LOOPS:
        return windows
    pick = np.linspace(0, len(windows) - 1, MAX_LOOPS).round().astype(int)
    return [windows[i] for i in pick]


def _hysteresis(pred: TrajectoryPrediction, against: str, title: str) -> bytes:
    """Friction near the reversals against velocity or against the position travelled since
    the reversal: measured as points, the model as lines, one colour per reversal."""
    f, unit = torque_scale(pred.friction_predicted)
    with styled():
        fig, axes = new_figure(width=7.0, height=4.6)
        ax = axes[0, 0]
        for k, idx in enumerate(_loops(pred)):
            if against == "velocity":
                x, scale = pred.velocity[idx], 1.0
            else:
                turn = idx[np.argmin(np.abs(pred.velocity[idx]))]
                x, scale = pred.position[idx] - pred.position[turn], 1e3
            color = COLORS[k % len(COLORS)]
            ax.plot(x * scale, pred.friction[idx] * f, ".", ms=2.5, alpha=0.5, color=color)
            ax.plot(x * scale, pred.friction_predicted[idx] * f, "-", lw=1.0, color=color)
        ax.plot([], [], ".", color="0.4", label="measured (torque − inertia − gravity)")
        ax.plot([], [], "-", color="0.4", label="model")
        ax.set_xlabel(
            "velocity [rad/s]" if against == "velocity" else "position since the reversal [mrad]"
        )
        ax.set_ylabel(f"friction [{unit}]")
        ax.legend(loc="best")
        ax.set_title(title)
        return png(fig)


def metrics_frame(columns: dict[str, TrajectoryPrediction]) -> pd.DataFrame:
    """One row per metric, one column per log."""
    values = {name: pred.metrics() for name, pred in columns.items()}
    rows = [
        {"metric": label, **{name: m[key] for name, m in values.items()}}
        for key, label in METRICS.items()
    ]
    return pd.DataFrame(rows)


def joint_frame(fitted: FittedModel) -> pd.DataFrame:
    """The joint's inertia and gravity coefficients, as the model file records them."""
    units = {"inertia": "kg m²", "p_x": "N m", "p_y": "N m"}
    rows = []
    for name, row in fitted.provenance["trajectory"]["joint"].items():
        low, high = row.get("ci95_low"), row.get("ci95_high")
        rows.append(
            {
                "parameter": name,
                "value": row.get("value"),
                "unit": units.get(name, ""),
                "95% CI low": np.nan if low is None else low,
                "95% CI high": np.nan if high is None else high,
            }
        )
    return pd.DataFrame(rows)


def _log_figures(
    doc: Document, pred: TrajectoryPrediction, key: str, label: str, minimised: str
) -> None:
    sec = doc.section(f"Torque on {label}")
    sec.add(
        Figure(
            f"torque_{key}",
            f"Measured and predicted torque over time ({label})",
            _torque_over_time(pred, f"{label}: torque"),
            caption="The model along the measured motion (inverse dynamics: J times the "
            "acceleration, the friction law driven by the measured velocity, gravity). "
            "Residual = measured − predicted; the raw one holds the noise and, at each "
            "break-away, the derivative filter's smoothing of the acceleration's jump; "
            + minimised,
        )
    )
    sec.add(
        Figure(
            f"residual_velocity_{key}",
            f"Residuals against velocity ({label})",
            _residual_vs_velocity(pred, f"{label}: residual against velocity"),
            caption="Structure near zero velocity means the model misses the friction at the "
            "reversals; scatter elsewhere is noise.",
        )
    )


def _trust_line(fitted: FittedModel) -> str:
    """The verdict line of the trust record the model file carries (``fricid fit
    --trajectory`` stores it), "" without one."""
    from ..identify.trust import Trust

    record = fitted.trust
    if not isinstance(record, dict):
        return ""
    try:
        return Trust.from_dict(record).line()
    except (KeyError, TypeError, ValueError):
        return ""


def output_error_note(fitted: FittedModel) -> str:
    """Why the low-passed residual of the log is not what the identification minimised ("" when
    it is): the fit refined its estimate by output error (an encoder too coarse to drive the
    law with the measured velocity), whose residual was the simulated joint's."""
    info = fitted.provenance.get("trajectory", {})
    if not (info.get("output_error") or {}).get("applied"):
        return ""
    rms = (fitted.metrics or {}).get("rmse")
    own = f": RMS {rms:.4g} N m" if isinstance(rms, int | float) else ""
    return (
        "the fit minimised the low-passed torque error of the joint simulated along the log "
        f"(output error, as the encoder is too coarse to drive the law with the measured "
        f"velocity){own}; the law driven by the log's quantised velocity misses by more where "
        "the quantisation bites"
    )


def trajectory_report(
    fitted: FittedModel,
    prediction: TrajectoryPrediction,
    *,
    heldout: TrajectoryPrediction | None = None,
    log_label: str = "the log",
    heldout_label: str = "the held-out log",
    progress: Callable[[str], Any] | None = None,
) -> Document:
    """The report of ``fitted`` along ``prediction`` (and ``heldout``): module docstring.

    Parameters
    ----------
    fitted : a model from ``fricid fit --trajectory``.
    prediction, heldout : :func:`fricid.identify.trajectory_check.predict_trajectory` of it
        on the log (and on a second log it was not identified from).
    log_label, heldout_label : the logs' names in titles and tables.
    progress : called with the part being built.
    """
    say = progress or (lambda _label: None)
    info = fitted.provenance.get("trajectory", {})
    m = prediction.metrics()
    doc = Document(
        title=f"Trajectory model report: {fitted.model}",
        summary=f"The {fitted.model} friction model identified from a trajectory "
        f"(route {info.get('route', '–')}), run along {log_label}"
        + (f" and the held-out {heldout_label}" if heldout is not None else "")
        + ": predicted against measured torque, residuals, hysteresis at the reversals.",
        meta={
            "model": fitted.model,
            "identification data": fitted.provenance.get("source") or "–",
            "log in this report": f"{log_label} ({int(m['n'])} sample periods)",
            "RMS torque error on it [N m]": m["rmse"],
            "RMS torque error on it where it slides [N m]": m["rmse_sliding"],
            "RMS of its torque [N m]": m["signal_rms"],
            "created by fricid": fitted.provenance.get("fricid_version", "–"),
        },
    )
    verdict = _trust_line(fitted)
    if verdict:
        doc.meta["trust"] = verdict
    columns = {log_label: prediction}
    if heldout is not None:
        h = heldout.metrics()
        doc.meta["held-out log"] = f"{heldout_label} ({int(h['n'])} sample periods)"
        doc.meta["RMS torque error on the held-out log [N m]"] = h["rmse"]
        doc.meta["RMS torque error on the held-out log where it slides [N m]"] = h["rmse_sliding"]
        graded, scope = heldout_grading(fitted, heldout)
        doc.meta["held-out grading"] = f"{heldout_label}: {scope}"
        if graded is not None:
            doc.meta["trust"] = graded.line()
            doc.meta["torque scatter of the held-out log [N m]"] = graded.scatter
        columns[heldout_label] = heldout
    say("figures: torque and residuals")
    sec = doc.section("Prediction error")
    sec.add(
        Table(
            "metrics",
            "Torque prediction error per log",
            metrics_frame(columns),
            caption="Nothing is refitted on the held-out log."
            if heldout is not None
            else "Give a second log (fricid report MODEL LOG HELDOUT_LOG) for held-out validation.",
        )
    )
    note = output_error_note(fitted)
    minimised = f"{note}." if note else "the low-passed one is what the identification minimised."
    _log_figures(doc, prediction, "log", log_label, minimised)
    say("figures: hysteresis at the reversals")
    sec = doc.section("Hysteresis at the reversals")
    n_rev = len(prediction.reversals())
    if n_rev == 0:
        sec.add(Note("The log has no velocity reversal: no hysteresis to draw.", kind="warning"))
    else:
        shown = min(n_rev, MAX_LOOPS)
        where = (
            f"{shown} of the log's {n_rev} reversals, evenly spread; samples slower than "
            f"{100 * REVERSAL_SPEED:g} % of the largest speed"
        )
        sec.add(
            Figure(
                "hysteresis_velocity",
                "Friction against velocity near the reversals",
                _hysteresis(prediction, "velocity", f"{log_label}: friction near reversals"),
                caption=f"{where}. A dynamic model's loops (LuGre, Dahl) follow the measured "
                "ones; a static model draws one curve through them.",
            )
        )
        sec.add(
            Figure(
                "hysteresis_position",
                "Friction against the position travelled since the reversal (pre-sliding)",
                _hysteresis(prediction, "position", f"{log_label}: pre-sliding"),
                caption=f"{where}. The slope at the reversal is the bristle stiffness "
                "(sigma_0 in LuGre and Dahl).",
            )
        )
    if heldout is not None:
        say("figures: the held-out log")
        _log_figures(doc, heldout, "heldout", heldout_label, minimised)
    say("parameters")
    sec = doc.section("Parameters")
    directions = any(n.endswith(("_pos", "_neg")) for n in fitted.parameters)
    legend = f"{DIRECTIONS[1:-1]}." if directions else ""
    table = parameter_table(fitted)
    sec.add(Table("parameters", "Friction parameters", table, caption=legend, digits=5))
    note = fitted.provenance["trajectory"].get("gravity_note") or ""
    title = "The joint's inertia and gravity"
    sec.add(Table("joint", title, joint_frame(fitted), caption=note, digits=5))
    return doc
