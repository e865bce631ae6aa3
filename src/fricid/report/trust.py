"""The report's "Can I trust this?" section: renders the trust record, computes nothing.

The record (:class:`fricid.identify.trust.Trust`) is computed once, by
:func:`fricid.identify.trust.assess_trust` (``fricid fit``, the fleet and ``fricid report``
call it; a record stored in the model file is reused for the same samples and options); this
module turns it into the section's list and tables: data quality per set-point, convergence,
identifiability, held-out error against the measurement scatter (and where it came from),
operating range.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..identify.trust import DROPS, OWN_CV, Trust

__all__ = ["READINGS_STD", "quality_frame", "scatter_explanation", "trust_text"]

#: The quality table's column of the readings' scatter at a set-point: not the scatter the
#: verdict compares the error with (:func:`scatter_explanation`).
READINGS_STD = "readings std [N m]"


def quality_frame(rows: list[dict[str, Any]]) -> Any:
    """The quality rows as a table: set-point, kept, dropped by reason, the standard
    deviation of the readings kept (:data:`READINGS_STD`), the scatter between the merged
    runs' means, what eq. 7 of the BAS-RBFNN paper left along the position, flag, and what
    the row merged or why it was dropped."""
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
                **{f"dropped: {why}": r.get(k) for k, why in DROPS.items()},
                READINGS_STD: r.get("scatter"),
                "between runs [N m]": r.get("run_scatter"),
                "gravity residual [N m]": r.get("gravity_residual"),
                "high scatter": "HIGH" if r.get("flagged") else "",
                "what and why": r.get("note") or "",
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


def _error_line(trust: Trust) -> str:
    """The held-out (or in-sample) error against the scatter, with where it came from."""
    if np.isfinite(trust.heldout_ratio):
        if not trust.held_out:
            label = "in-sample RMSE"
        elif trust.heldout_scheme in trust.heldout_source:  # the source names the scheme
            label = f"held-out RMSE ({trust.heldout_source})"
        else:
            label = f"held-out RMSE ({trust.heldout_scheme}, {trust.heldout_source})"
        held = (
            f"{label} {trust.heldout_rmse:.3g} N m against a scatter of {trust.scatter:.3g} "
            f"N m: {trust.verdict}"
        )
    else:
        held = "no measurement scatter to compare with"
    if trust.validation_note:
        held += f" ({trust.validation_note})"
    cv = trust.cv or (trust.validation if trust.heldout_source == OWN_CV else None)
    if cv and cv.get("rmse") is not None:
        held += (
            f"; the fit's own cross-validation ({cv.get('scheme')}): {cv['rmse']:.3g} N m, "
            f"{cv.get('verdict', '')}: {cv.get('note', '')}"
        )
    if trust.what_to_do:
        held += f". What to do: {trust.what_to_do}"
    return held


def scatter_explanation(trust: Trust) -> str:
    """Why the quality table's readings std differs from the scatter of the verdict: one is
    the spread of single readings at a set-point, the other the scatter of the samples the
    model is fitted to (each a mean of many readings), which is what an error is compared
    with."""
    sc = (
        f"the measurement scatter of the samples, {trust.scatter:.3g} N m"
        if np.isfinite(trust.scatter)
        else "the measurement scatter of the samples"
    )
    return (
        f"The '{READINGS_STD}' column is the spread of the single readings kept at a "
        f"set-point. The verdict compares the model's error with {sc}: each sample is the "
        "mean of many readings, so its scatter is smaller, by about the square root of the "
        "readings averaged (or measured between repeated passes). The verdict's number is "
        "the one to compare the RMSE with."
    )


def trust_text(trust: Trust) -> str:
    """The section's list: data quality, convergence, identifiability, held-out error,
    operating range (plain text with the report's small markup)."""
    lines = [f"- **Data quality**: {trust.quality_summary}."]
    conv = f"- **Convergence**: {trust.convergence}"
    if trust.advice:
        conv += f". What to do: {trust.advice}"
    lines.append(conv + ".")
    ident = []
    if trust.learned:
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
    lines.append(f"- **Error against scatter**: {_error_line(trust)}.")
    if np.isfinite(trust.scatter):
        table = (  # only where there is a table to point at
            "; the readings' spread per set-point in the data-quality table is larger (each "
            "sample averages many readings)"
            if trust.quality
            else ""
        )
        lines.append(
            f"- **Measurement scatter** (the one number every comparison here uses): "
            f"{trust.scatter:.3g} N m, the scatter of the samples the model was fitted to"
            f"{table}."
        )
    lines.append(
        f"- **Operating range** (predictions outside it are extrapolated): "
        f"{trust.range or 'not recorded'}."
    )
    return "\n".join(lines)
