"""``fricid reproduce rwsavsbas``: the RWSAVSBAS paper's tables and figures as a document.

[R] Kou et al., "A New Parameter Identification Method for Industrial Robots with Friction",
Machines 10(5) 349, 2022. Composes :func:`fricid.experiments.rwsavsbas_paper.run_rwsavsbas`'s
result: Fig. 3/4 (friction against velocity with the Stribeck construction), Table 1 and
Fig. 6 (8 runs of VSBAS, IBAS and RWSAVSBAS: fitness statistics and average convergence
curves), Fig. 7 (error per sampling point at each algorithm's best run), Table 2 (identified
parameters) and Fig. 8 (predicted curve over the measurements), on the virtual joint and, per
direction, on the real lead-screw recordings. Each table puts [R]'s numbers beside ours.
"""

from __future__ import annotations

import os
from collections.abc import Callable

import numpy as np
import pandas as pd

from ...experiments.paper_numbers import RWSAVSBAS as PAPER
from ...experiments.rwsavsbas_paper import (
    FIXED,
    PAPER_METHODS,
    PARAMS,
    STEPS,
    Comparison,
    DatasetResult,
    RwsavsbasResult,
    run_rwsavsbas,
)
from ...fitted import FittedModel
from ...models import get_model
from ...sim import preset
from .. import paper_plots as pp
from .. import plots
from ..document import Document, Figure, Note, Section, Table
from ._fig6 import coincide, fig6_convergence
from .stribeck import headline, study_notes

__all__ = ["STEPS", "build_rwsavsbas", "compose_rwsavsbas"]

_SYMBOLS = {
    "tau_c": "τc [N m]",
    "tau_s": "τs [N m]",
    "w_s": "ws [rad/s]",
    "tau_v": "τv [N m s/rad]",
}


def _table1(tag: str, comp: Comparison, *, paper_numbers: bool) -> Table:
    """[R] Table 1: final SSE of each method's runs, the paper's beside ours."""
    f_opt = comp.optimum[1]
    groups = comp.study.table["group"] if comp.study is not None else {}
    rows = []
    for label, runs in comp.results.items():
        f = np.array([r.fun for r in runs])
        in_paper = label in PAPER_METHODS
        p = PAPER["table1"].get(label.lower()) if in_paper and paper_numbers else None
        rows.append(
            {
                "algorithm": label if in_paper else f"{label} (not in the paper)",
                "budget": groups.get(
                    label, "paper budget" if len(groups) else "paper's iterations"
                ),
                "paper: average": p["mean"] if p else np.nan,
                "ours: average": f.mean(),
                "paper: max": p["max"] if p else np.nan,
                "ours: max": f.max(),
                "paper: min": p["min"] if p else np.nan,
                "ours: min": f.min(),
                "ours: average / optimum": f.mean() / f_opt,
                "runs at the optimum (0.1 %)": f"{int(np.sum(f <= f_opt * 1.001))}/{len(f)}",
                "evaluations per run": int(max(r.nfev for r in runs)),
                "setting": comp.settings.get(label, ""),
            }
        )
    caption = (
        f"Fitness = SSE over the {len(comp.samples)} samples (eq. 11, N² m²), "
        f"{PAPER['runs']} runs per algorithm. The exact optimum (variable projection, "
        f"a baseline the paper did not have) is SSE {f_opt:.4g}: the ratio column says "
        "how close each algorithm gets. Every method evaluates the same compiled objective; "
        + (
            "the rows at RWSAVSBAS's evaluation count ('equal budget') come first: "
            + headline(comp.study)
            if comp.study is not None
            else "each runs the paper's iterations, so their evaluations per run differ (that "
            "column): this compares the paper's settings, not equal budgets."
        )
    )
    notes = study_notes(comp.study) if comp.study is not None else []
    if notes:
        caption += " Where ours differ from the paper: " + " ".join(notes)
    if not paper_numbers:
        peak = float(np.max(np.abs(comp.samples.friction)))
        caption += (
            " The paper's numbers are for its robot's 17 samples and are not shown "
            f"here: this is a different drive, with friction up to {1e3 * peak:.3g} mN m "
            f"(optimal SSE {f_opt:.3g} N² m²)."
        )
    return Table(
        f"{tag}_table1_fitness",
        "Table 1. Comparison of the average adaptation "
        f"degree (fitness) of each algorithm ({_label(tag)})",
        pd.DataFrame(rows),
        caption=caption,
    )


def _label(tag: str) -> str:
    return {
        "virtual": "virtual joint",
        "leadscrew_pos": "lead screw, positive direction as the drive records it",
        "leadscrew_neg": "lead screw, negative direction as the drive records it",
    }.get(tag, tag)


def _fig6(tag: str, comp: Comparison, *, paper_numbers: bool) -> Figure:
    """[R] Fig. 6: the average convergence curves of the paper's three methods."""
    hist = {label: [np.asarray(r.history) for r in comp.results[label]] for label in PAPER_METHODS}
    f_opt = comp.optimum[1]
    paper_rws = PAPER["table1"]["rwsavsbas"]["mean"]
    paper = ("paper: RWSAVSBAS average", paper_rws) if paper_numbers else None
    png = fig6_convergence(
        hist,
        title=f"Fig. 6: average convergence over {PAPER['runs']} runs ({_label(tag)})",
        optimum=f_opt,
        paper=paper,
    )
    if paper is None:
        refs = f"The grey band is the exact optimum (SSE {f_opt:.3g})."
    elif coincide(f_opt, paper_rws):
        refs = (
            f"The grey band is the exact optimum (SSE {f_opt:.3g}), the dashed line with "
            f"diamonds the paper's RWSAVSBAS average ({paper_rws:.3g}): they coincide (ratio "
            f"{paper_rws / f_opt:.3g}) because the preset's noise is calibrated to the paper's "
            "optimum, so both are drawn apart in style."
        )
    else:
        refs = (
            f"The grey band is the exact optimum (SSE {f_opt:.3g}), the dashed line with "
            f"diamonds the paper's RWSAVSBAS average ({paper_rws:.3g}; ratio "
            f"{paper_rws / f_opt:.3g})."
        )
    return Figure(
        f"{tag}_fig6_convergence",
        f"Fig. 6. Average adaptation (fitness) curves over {PAPER['runs']} runs ({_label(tag)})",
        png,
        caption=(
            f"Paper: {PAPER['figures']['fig6']} Ours: the mean best-so-far SSE "
            "against objective evaluations (one candidate scored is one evaluation; "
            "an RWSAVSBAS iteration costs about 300 of them, a VSBAS or IBAS "
            "iteration 3, so iterations would not compare equal work), log axes. " + refs
        ),
    )


def _fig7(data: DatasetResult) -> Figure:
    """[R] Fig. 7: the error at each sampling point, best run of each paper method."""
    tag, errors = data.tag, data.errors
    png = pp.error_per_point(
        data.samples.velocity,
        errors,
        velocity_unit=data.velocity_unit,
        title=f"Fig. 7: error at each sampling point, best run of each algorithm ({_label(tag)})",
    )
    big = {k: float(np.max(np.abs(v))) for k, v in errors.items()}
    return Figure(
        f"{tag}_fig7_errors",
        f"Fig. 7. Comparison of the minimum error of friction torque ({_label(tag)})",
        png,
        caption=(
            f"Paper: {PAPER['figures']['fig7']} Ours: largest |error| "
            + ", ".join(f"{k} {1e3 * v:.3g} mN m" for k, v in big.items())
            + "."
            + (_fig7_against_paper(data.comparison, big) if data.paper_numbers else "")
        ),
    )


def _fig7_against_paper(comp: Comparison, big: dict[str, float]) -> str:
    """Our VSBAS and IBAS against [R]'s, computed: average SSE (Table 1) and the largest error
    at the best run (Fig. 7's text), each said lower or not."""
    paper_err = PAPER["fig7"]["vsbas_ibas_max"]
    parts = []
    for label in ("VSBAS", "IBAS"):
        ours = float(np.mean([r.fun for r in comp.results[label]]))
        theirs = PAPER["table1"][label.lower()]["mean"]
        parts.append(
            f"{label}: average SSE {ours:.3g} against the paper's {theirs:.3g} "
            f"({'lower' if ours < theirs else 'not lower'}), largest error {1e3 * big[label]:.3g} "
            f"mN m against the paper's about {1e3 * paper_err:.3g} mN m "
            f"({'smaller' if big[label] < paper_err else 'not smaller'})"
        )
    return " " + "; ".join(parts) + "."


def _readings(tag: str, result) -> Table:
    """The readings of RWSAVSBAS where [R] is unclear (not in the paper)."""
    extra = result.readings.reset_index()[["label", "mean_ratio", "max_ratio", "found", "runs"]]
    extra.columns = [
        "reading of RWSAVSBAS",
        "average SSE / optimum",
        "worst SSE / optimum",
        "runs at the optimum",
        "runs",
    ]
    return Table(
        f"{tag}_rwsavsbas_readings",
        "Readings of RWSAVSBAS where the paper is unclear (not in the paper)",
        extra,
        caption=(
            "The paper leaves the wandering antenna's direction, the phase P "
            "and when the global best is updated open; fricid's default is "
            "the first row. All readings at the paper's settings."
        ),
    )


def _dataset_section(doc: Document, title: str, data: DatasetResult) -> None:
    """One data set's section: Table 1, Fig. 6, Fig. 7, the readings (virtual joint), Table 2,
    Fig. 3/4 and Fig. 8."""
    tag, comp, samples = data.tag, data.comparison, data.samples
    truth, paper_numbers, velocity_unit = data.truth, data.paper_numbers, data.velocity_unit
    sec: Section = doc.section(title)
    label = "RWSAVSBAS, best of 8 runs"
    sec.add(_table1(tag, comp, paper_numbers=paper_numbers))
    sec.add(_fig6(tag, comp, paper_numbers=paper_numbers))
    sec.add(_fig7(data))
    if comp.study is not None:
        sec.add(_readings(tag, comp.study))
    best, reference = data.best, data.reference
    sec.add(
        _table2(tag, best, reference, truth=truth, paper_numbers=paper_numbers, best_label=label)
    )
    sign = -1.0 if (samples.velocity < 0).all() else 1.0
    sec.add(
        Figure(
            f"{tag}_fig3_fig4_stribeck",
            f"Fig. 3/4. Friction against velocity and the Stribeck construction ({_label(tag)})",
            pp.stribeck_construction(
                samples.velocity,
                samples.friction,
                best.params,
                velocity_unit=velocity_unit,
                label=label,
                title="Fig. 3/4: measured friction and the "
                "Stribeck model" + (" (negative direction, magnitudes)" if sign < 0 else ""),
            ),
            caption=(
                f"Paper: Fig. 3: {PAPER['figures']['fig3']} Fig. 4: "
                f"{PAPER['figures']['fig4']} Ours: both in one figure, on "
                "our data, with the identified parameters; the right panel enlarges "
                "the Stribeck region. The paper's Fig. 4 is a sketch; ours is drawn "
                "from the fit."
            ),
        )
    )
    models = {label: best.predict}
    if truth is not None:
        theta = get_model("stribeck").param_vector({**truth, **FIXED})
        models["true law (= paper's Table 2)"] = lambda X: get_model("stribeck").predict(theta, X)
    sec.add(
        Figure(
            f"{tag}_fig8_prediction",
            f"Fig. 8. Friction torque prediction curve ({_label(tag)})",
            plots.friction_curves(
                samples,
                models,
                velocity_unit=velocity_unit,
                title="Fig. 8: predicted friction over the measurements",
            ),
            caption=(
                f"Paper: {PAPER['figures']['fig8']} Ours: the same, on a log "
                "velocity axis so that the Stribeck region is visible"
                + ("; the true law of the virtual joint is drawn too." if truth else ".")
                + f" Fit: SSE {best.metrics['sse']:.3g} N² m², "
                f"R² {best.metrics['fitness']:.4f}."
            ),
        )
    )


def _table2(
    tag: str,
    best: FittedModel,
    reference: FittedModel,
    *,
    truth: dict | None,
    paper_numbers: bool,
    best_label: str,
) -> Table:
    rows = []
    for name in PARAMS:
        row = {"parameter": _SYMBOLS[name]}
        if paper_numbers:
            row["paper (Table 2)"] = PAPER["table2"][name]
        if truth is not None:
            row["virtual joint (true)"] = truth[name]
        row[f"ours: {best_label}"] = best.params[name]
        row["ours: 95% CI ±"] = best.parameters[name].ci95_halfwidth
        row[f"{reference.optimizer.method} (reference)"] = reference.params[name]
        rows.append(row)
    last = {"parameter": "SSE [N² m²]"}
    if paper_numbers:
        last["paper (Table 2)"] = PAPER["table1"]["rwsavsbas"]["min"]
    if truth is not None:
        last["virtual joint (true)"] = np.nan
    last.update(
        {
            f"ours: {best_label}": best.metrics["sse"],
            "ours: 95% CI ±": np.nan,
            f"{reference.optimizer.method} (reference)": reference.metrics["sse"],
        }
    )
    rows.append(last)
    caption = (
        "Stribeck model eq. 7 with δ fixed to 1 (Tustin), fitted by minimising the SSE "
        "(eq. 11). 95 % CI from the Jacobian at the optimum. The reference column is a "
        "baseline the paper did not run: the best possible fit."
    )
    if truth is not None:
        caption += (
            " The virtual joint was built with the paper's Table 2 values, so the "
            "truth column equals the paper's; ours differs from it by the measurement "
            "noise the preset adds, calibrated so that the optimal SSE is near the paper's "
            f"{PAPER['table1']['rwsavsbas']['min']:.2g} (ours {reference.metrics['sse']:.3g}): "
            "a calibration, not a reproduction."
        )
    else:
        caption += (
            " The paper's values belong to its robot and are not comparable to this "
            "lead screw (its friction range: Table 1's caption), so they are not repeated here."
        )
    return Table(
        f"{tag}_table2_parameters",
        f"Table 2. Stribeck model identification parameter values ({_label(tag)})",
        pd.DataFrame(rows),
        caption=caption,
    )


# -- the whole paper ---------------------------------------------------------------------------


def compose_rwsavsbas(result: RwsavsbasResult) -> Document:
    """The reproduction of [R] as a document.

    Parameters
    ----------
    result : fricid.experiments.rwsavsbas_paper.RwsavsbasResult
        The computed study.

    Returns
    -------
    Document
        To be written with :func:`fricid.report.write_document`.
    """
    samples = result.virtual.samples
    scenario = preset("paper2", "full")
    folder, quick, seed = result.folder, result.quick, result.seed
    doc = Document(
        title=f"Reproduction: {PAPER['short']}",
        summary=(
            f"Kou et al., “{PAPER['title']}” (Machines 2022): every table and figure "
            "regenerated on fricid's virtual joint, then on a real lead-screw drive, per "
            "direction of motion. Each table puts the paper's published numbers beside "
            "ours; each figure's caption says what the paper showed and why ours differs "
            "where it does."
        ),
        meta={
            "virtual joint": f"paper2 preset, full design, {len(samples)} samples",
            "real data": str(folder) if folder else "not found",
            "seed": seed,
            "mode": "quick (reduced optimiser budgets)"
            if quick
            else "full (8 runs × 1000 iterations per algorithm)",
            "algorithm study": "fricid.experiments.stribeck_study",
        },
    )
    doc.section(
        "The data",
        "The paper's experiment (section 2.1) on the virtual joint: a "
        "horizontal joint moved at constant velocity both ways, friction = half the "
        "difference of the two directions' torques (eq. 5).\n\n" + scenario.description,
    )
    _dataset_section(doc, "Virtual joint (paper2 preset)", result.virtual)
    if folder is None:
        doc.section("Real lead-screw drive").add(
            Note(
                "The lead-screw recordings were not found (set FRICID_LEADSCREW_DIR or run beside "
                "shared/data/real/epos-leadscrew).",
                kind="warning",
            )
        )
        return doc
    doc.section(
        "Real lead-screw drive",
        (
            "Mablekos-Alexiou et al. (IEEE T-RO 2021), a Maxon motor on a simple lead screw, "
            "one steady velocity per recording (2-200 rpm, both directions); friction = the mean "
            "motor torque of each recording. The paper's eq. 7 has one parameter set, so it is "
            f"identified per direction{_asymmetry(result)}. The directions are the drive's as it "
            "records them (the motor's sign convention; fricid extract --flip-sign turns them "
            "into the joint's, so the README's forwards is the negative direction here). The "
            "search box scales with the data "
            "(fricid.experiments.rwsavsbas_paper.scaled_bounds); the paper's numbers are for its "
            "robot and are not repeated."
        ),
    )
    for direction, data in result.leadscrew.items():
        _dataset_section(doc, f"Lead screw, {direction} direction", data)
    return doc


def _asymmetry(result: RwsavsbasResult) -> str:
    """The lead screw's friction at its slowest recording per direction, computed."""
    parts = []
    for direction, data in result.leadscrew.items():
        v, f = np.abs(data.samples.velocity), np.abs(data.samples.friction)
        i = int(np.argmin(v))
        parts.append(f"{1e3 * f[i]:.2g} mN m {direction} at {v[i] * 60 / (2 * np.pi):.3g} rpm")
    return "; at the slowest recording: " + ", ".join(parts) if parts else ""


def build_rwsavsbas(
    *,
    quick: bool = False,
    seed: int = 0,
    progress: Callable[[str], None] | None = None,
    leadscrew: str | os.PathLike[str] | None = None,
) -> Document:
    """Run [R]'s study (:func:`~fricid.experiments.rwsavsbas_paper.run_rwsavsbas`, same
    parameters) and compose its document (:func:`compose_rwsavsbas`)."""
    return compose_rwsavsbas(
        run_rwsavsbas(quick=quick, seed=seed, progress=progress, leadscrew=leadscrew)
    )
