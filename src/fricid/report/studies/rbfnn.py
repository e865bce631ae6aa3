"""The BAS-RBFNN network study as ``fricid bench rbfnn`` shows it: Markdown, CSV, Fig. 9-10.

Renders :func:`fricid.experiments.rbfnn_study.run_study`'s result: :func:`study_notes` (how
the study reads the paper), :func:`summary_markdown` (every table, the notes, the settings and
the stage times) and :func:`write_outputs` (CSV tables, [B] Fig. 9 and Fig. 10 as PNG drawn
by :mod:`fricid.report.paper_plots`, ``summary.md``; each file written atomically).

[B] "An Optimized RBF Neural Network Based on Beetle Antennae Search Algorithm for Modeling the
Static Friction in a Robotic Manipulator Joint".
"""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

import pandas as pd

from ...experiments.paper_numbers import table1_rmse_unit
from ...experiments.rbfnn_study import PAPER, TUNING_SEED_OFFSET, StudyResult
from ...io.atomic import atomic_write
from ...units import DEG
from .. import paper_plots as pp

__all__ = [
    "FIG9_MODELS",
    "FIG10_MODELS",
    "fig9_png",
    "fig10_png",
    "search_note",
    "study_notes",
    "summary_markdown",
    "tuning_note",
    "warnings_note",
    "write_outputs",
]

#: The methods of [B] Fig. 9, in order.
FIG9_MODELS = ("GA-RBFNN", "BAS-RBFNN")

#: The models drawn in Fig. 10, in order (those the study computed).
FIG10_MODELS = ("BAS-RBFNN", "RBFNN", "VLT model", "MLP", "GP")


def study_notes(result: StudyResult) -> list[str]:
    """How the study reads [B]: the target MSE's scale, what an epoch costs, the tuned
    constants, the encoding, the inputs and how the timings were taken.

    Parameters
    ----------
    result : fricid.experiments.rbfnn_study.StudyResult
        The study.

    Returns
    -------
    list of str
        One note per line, the timing note last.
    """
    cfg, data_table = result.config, result.tables["data"]
    return [
        f"Target MSE {cfg.target_mse:g} is on the friction mapped onto [-1, 1] (MATLAB "
        f"mapminmax): an RMSE of {data_table['target_rmse_mNm'].iloc[0]:.3f} mN m here.",
        f"One epoch = {cfg.evals_per_epoch} candidate networks evaluated: one GA generation "
        f"(population {cfg.evals_per_epoch} + 2 elites), {cfg.evals_per_epoch // 2} BAS "
        "iterations (the two antennae of eq. 19 each; the position is not evaluated, as in "
        "eq. 18-21).",
        tuning_note(result),
        "The row 'BAS-RBFNN (eq. 21 constants)' keeps the paper's 0.95 / 0.01 / 0.95; GA's "
        "population starts around the least-squares network (init_spread), as BAS starts "
        "from it.",
        search_note(result),
        warnings_note(result),
        "BAS-RBFNN and GA-RBFNN search centres and widths with least-squares output weights "
        "(hybrid encoding) from the RBFNN network; the full encoding (the paper's description) "
        "is shown in Table 4's variant rows when computed.",
        (
            "Inputs of the networks, the MLP and the GP: velocity warped by asinh(v / "
            f"{cfg.velocity_scale / DEG:g} deg/s), then standardised; 'RBFNN, plain inputs' "
            "omits the warp, as the paper."
            if cfg.velocity_scale is not None
            else "Inputs: standardised velocity, load and temperature, as the paper."
        ),
        "Timings use one BLAS and OpenMP thread (table 'timing'), and again the libraries' "
        "default threads, all cores ('timing_all_threads'), with the same statistic for every "
        "model: "
        f"{max(1, cfg.timing_repeats)} fits for each of {cfg.seeds} seeds (the models in "
        "turn), each seed's best wall time, then the median over the seeds (and the slowest "
        "seed). fit_s in Table 3 is the wall time of the all-data fit in this run (threads as "
        "configured).",
    ]


def tuning_note(result: StudyResult) -> str:
    """How the settings were picked: on what data and seeds, the choice and the budgets."""
    t = result.tables.get("tuning")
    if t is None or t.empty:
        return "Settings as given (no tuning run): BAS, GA and MLP options of the configuration."
    chosen = t[t["chosen"]]
    picks = "; ".join(f"{r.learner}: {r.setting}" for r in chosen.itertuples())
    budgets = "; ".join(f"{r.learner} {r.budget}" for r in chosen.itertuples())
    return (
        f"Settings tuned on {t['tuning_data'].iloc[0]} (not the reported data), with search "
        f"seeds {result.config.seed + TUNING_SEED_OFFSET}.. (not the reported ones), by "
        f"held-out RMSE: {picks}. Tuning budgets: {budgets}."
    )


def search_note(result: StudyResult) -> str:
    """What BAS-RBFNN's search achieved from its least-squares start (computed)."""
    s = result.tables.get("search")
    if s is None or s.empty:
        return "BAS-RBFNN's search against its start: not computed."
    folds = s[s["fit"] != "all data"]
    n_imp = int(folds["improved"].sum())
    worse = int((folds["heldout_change_pct"] > 0).sum())
    alld = s[s["fit"] == "all data"].iloc[0]
    return (
        f"BAS-RBFNN's search from its start (the RBFNN network): improved the training MSE in "
        f"{n_imp} of {len(folds)} folds (median change "
        f"{float(folds['train_change_pct'].median()):+.3g} %; a search that finds nothing "
        "better returns its start, so 'BAS-RBFNN <= RBFNN' on training data says nothing); "
        f"held out, the fold RMSE changed by {float(folds['heldout_change_pct'].median()):+.3g} "
        f"% (median), worse in {worse} of {len(folds)} folds; on all data the training MSE "
        f"changed {float(alld['train_change_pct']):+.3g} %."
    )


def warnings_note(result: StudyResult) -> str:
    """The warnings the learners raised while fitting (recorded, not silenced)."""
    t3 = result.tables["table3"]
    if "warnings" not in t3:
        return "Warnings while fitting: not recorded."
    hit = t3[t3["warnings"] > 0]
    if hit.empty:
        return "No learner raised a warning while fitting (all data and every fold)."
    return (
        "Warnings while fitting (all data and every fold, not silenced): "
        + "; ".join(f"{r.model} {int(r.warnings)} ({r.warning_kinds})" for r in hit.itertuples())
        + "."
    )


def _fmt(df: pd.DataFrame) -> str:
    """A table as a fixed-width text block in Markdown."""
    return "```\n" + df.to_string(index=False, float_format=lambda v: f"{v:.4g}") + "\n```"


def summary_markdown(result: StudyResult) -> str:
    """The study's report as Markdown: every table, the notes and the stage times."""
    t = result.tables
    parts = [
        "# BAS-RBFNN study on the virtual joint (paper1 preset)",
        "",
        "Errors in mN m; the paper's columns converted from N m.",
        "",
        "## Data",
        "",
        _fmt(t["data"]),
        "",
        "## Table 1",
        "",
        _fmt(t["table1"]),
        "",
        table1_rmse_unit(),
        "",
        "## Tuning (on data and seeds not reported)",
        "",
        _fmt(t["tuning"].drop(columns=["tuning_data", "budget"]))
        if "tuning" in t and not t["tuning"].empty
        else "(not run)",
        "",
        "## Table 3 (all data as training set, and k-fold out-of-fold)",
        "",
        _fmt(t["table3"].drop(columns="warning_kinds", errors="ignore")),
        "",
        "## What BAS-RBFNN's search achieved from its start (the RBFNN network)",
        "",
        _fmt(t["search"]) if "search" in t and not t["search"].empty else "(not computed)",
        "",
        "## Table 4 and Fig. 9",
        "",
        _fmt(t["table4"]),
        "",
        _fmt(t["table4_runs"]),
        "",
        "## Fig. 10 (unseen region)",
        "",
        _fmt(t["fig10"]),
        "",
        "## Training time on all data",
        "",
        _fmt(t["timing"]),
        "",
        "## Performance targets",
        "",
        _fmt(t["targets"]),
        "",
        "## Notes",
        "",
    ]
    parts += [f"- {n}" for n in study_notes(result)]
    parts += [
        "",
        "## Configuration",
        "",
        "```",
        *(f"{k} = {v!r}" for k, v in asdict(result.config).items()),
        "```",
        "",
        "## Stage times",
        "",
    ]
    parts += [f"- {k}: {v:.1f} s" for k, v in result.seconds.items()]
    return "\n".join(parts) + "\n"


def fig9_png(result: StudyResult, *, variants: bool = False) -> bytes:
    """[B] Fig. 9: training MSE against epochs, GA-RBFNN and BAS-RBFNN (``variants``: every
    row of Table 4), each run a thin line, the median thick, the target and the paper's epoch
    marked (:func:`fricid.report.paper_plots.mse_curves`)."""
    curves = result.curves
    if variants:
        return pp.mse_curves(
            curves,
            result.config.target_mse,
            title="Training MSE of every Table 4 variant",
            ncols=4,
            sharey=False,
        )
    main = {m: curves[m] for m in FIG9_MODELS if m in curves}
    return pp.mse_curves(
        main,
        result.config.target_mse,
        paper_epochs={m: PAPER["table4"][m]["epochs"] for m in main},
        title="Fig. 9: training MSE of GA-RBFNN and BAS-RBFNN",
        ncols=2,
        log_epochs=True,
    )


def fig10_png(result: StudyResult) -> bytes:
    """[B] Fig. 10: absolute errors in the unseen region
    (:func:`fricid.report.paper_plots.unseen_region`), BAS-RBFNN highlighted."""
    unseen = result.unseen
    return pp.unseen_region(
        unseen["temperature"],
        {m: unseen[m] for m in FIG10_MODELS if m in unseen},
        title="Fig. 10: prediction errors beyond the experimental area",
        highlight="BAS-RBFNN",
        train_max_temperature=45.0,
        paper=PAPER["fig10"],
    )


def write_outputs(result: StudyResult, out: str | Path) -> list[Path]:
    """Write the study into the folder ``out`` (created).

    Parameters
    ----------
    result : fricid.experiments.rbfnn_study.StudyResult
        The study.
    out : path-like
        Receives every table as ``<name>.csv``, ``fig9_mse.png`` (and ``fig9_variants.png``
        when Table 4 has variants), ``fig10_unseen.png`` and ``summary.md``, each written
        atomically (:mod:`fricid.io.atomic`).

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, df in result.tables.items():
        path = out / f"{name}.csv"
        with atomic_write(path, "w") as fh:
            df.to_csv(fh, index=False)
        paths.append(path)
    figures = [("fig9_mse.png", fig9_png(result))]
    if set(result.curves) - set(FIG9_MODELS):
        figures.append(("fig9_variants.png", fig9_png(result, variants=True)))
    figures.append(("fig10_unseen.png", fig10_png(result)))
    for name, data in figures:
        path = out / name
        with atomic_write(path, "wb") as fh:
            fh.write(data)
        paths.append(path)
    path = out / "summary.md"
    with atomic_write(path, "w") as fh:
        fh.write(summary_markdown(result))
    paths.append(path)
    return paths
