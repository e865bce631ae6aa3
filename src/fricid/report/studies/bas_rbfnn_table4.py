"""The BAS-RBFNN reproduction's Table 4 and Fig. 9: GA-RBFNN against BAS-RBFNN.

[B] section 4.3, Table 4 and Fig. 9 (epochs to the target MSE 1e-4: 356 for GA, 257 for BAS),
composed from :func:`fricid.experiments.rbfnn_study.run_study`'s ``table4``,
``table4_runs`` and ``curves``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ...experiments.paper_numbers import BAS_RBFNN as PAPER
from ...experiments.rbfnn_study import BAS_PAPER
from ..document import Figure, Table
from ._bas_rbfnn_common import T4_PAPER, epochs, quick_setting
from .rbfnn import FIG9_MODELS, fig9_png

__all__ = ["fig9_items", "table4_items"]


def table4_items(res, quick: bool, claims: dict[str, bool]) -> list:
    """[B] Table 4 (GA-RBFNN against BAS-RBFNN over seeds) and its run-by-run table."""
    t4 = res.tables["table4"]
    cfg = res.config
    paper = PAPER["table4"]
    rows = []
    for _, r in t4.iterrows():
        key = T4_PAPER.get(r["model"])
        p = paper[key] if key else {}
        med = float(r["epochs_median"])
        rng = (
            f"{r['epochs_min']:.0f}-{r['epochs_max']:.0f}" if np.isfinite(r["epochs_min"]) else "–"
        )
        rows.append(
            {
                "model": r["model"],
                "paper: epochs to target": PAPER["fig9"]["epochs"][key] if key else np.nan,
                f"ours: epochs to target, median of {int(r['runs'])}": (
                    med if np.isfinite(med) else np.nan
                ),
                "ours: runs that reached it": f"{int(r['reached_target'])}/{int(r['runs'])}",
                "ours: epochs range": rng,
                "paper: mean [mN m]": 1e3 * p.get("mean", np.nan),
                "ours: mean [mN m]": r["mean_mNm"],
                "paper: max [mN m]": 1e3 * p.get("max", np.nan),
                "ours: max [mN m]": r["max_mNm"],
                "ours: seconds per run": r["seconds_mean"],
            }
        )
    by = t4.set_index("model")
    ga, bas = by.loc["GA-RBFNN"], by.loc["BAS-RBFNN"]
    target_rmse = float(res.tables["data"]["target_rmse_mNm"].iloc[0])
    parts = [
        f"Each method trained on all data {cfg.seeds} times (seeds {cfg.seed}-"
        f"{cfg.seed + cfg.seeds - 1}) to the paper's target MSE {cfg.target_mse:g} (on the "
        f"friction scaled to [-1, 1]: an RMSE of {target_rmse:.3g} mN m here), at most "
        f"{cfg.max_epochs} epochs of {cfg.evals_per_epoch} candidate networks; the paper "
        "reports one run each and does not say what an epoch costs. Both start from the "
        "RBFNN network and search its centres and widths, the output weights solved by "
        "least squares (hybrid encoding). A dash: the median run did not reach the target. "
        "Errors: mean over runs of the mean and maximum absolute error on all data; the "
        "paper's in N m, shown in mN m.",
    ]
    reached_b, reached_g = int(bas["reached_target"]), int(ga["reached_target"])
    if reached_b == 0 and reached_g == 0:
        parts.append(
            "Neither method reached the target in any run"
            + (
                f" (quick settings: {quick_setting(res)}): Table 4 "
                "compares the final MSE and errors only; run without --quick for epochs."
                if quick
                else f" within {cfg.max_epochs} epochs."
            )
        )
    else:
        eb, eg = float(bas["epochs_median"]), float(ga["epochs_median"])
        verdict = (
            "BAS-RBFNN needs fewer epochs than GA-RBFNN, as in the paper"
            if claims["table4_bas_fewer_epochs"]
            else "Unlike the paper, BAS-RBFNN does not need fewer epochs than GA-RBFNN"
        )
        parts.append(
            f"{verdict}: median {epochs(eb)} against {epochs(eg)} (reached in {reached_b} and "
            f"{reached_g} of {cfg.seeds} runs; the paper's "
            f"{PAPER['fig9']['epochs']['bas_rbfnn']:g} against "
            f"{PAPER['fig9']['epochs']['ga_rbfnn']:g}, one run each)."
        )
    eq21 = (
        by.loc["BAS-RBFNN (eq. 21 constants)"]
        if "BAS-RBFNN (eq. 21 constants)" in by.index
        else None
    )
    ours, printed = cfg.bas_options, BAS_PAPER
    floor_ours = ours["d_inc"] / (1.0 - ours["eta_d"])
    floor_paper = printed["d_inc"] / (1.0 - printed["eta_d"])
    tuned = (
        "How large BAS's advantage is depends on its constants: ours uses eq. 21's form with "
        f"constants tuned on other data and seeds than reported (antenna floor "
        f"{floor_ours:g} instead of {floor_paper:g}, step decay {ours['eta_step']:g} instead "
        f"of {printed['eta_step']:g} per iteration; GA's mutation index and the spread of its "
        "population around the least-squares network tuned likewise, on the same budget). With "
        "the constants as printed the step falls to "
        f"{100 * printed['eta_step'] ** 100:.2g} % of its start within 100 iterations while "
        f"the antennae stay near {floor_paper:g}, so its search narrows early"
    )
    if eq21 is not None:
        e21, eg = float(eq21["epochs_median"]), float(ga["epochs_median"])
        eb = float(bas["epochs_median"])
        slowest = float(eq21["epochs_max"])
        tuned += (
            ": the row 'BAS-RBFNN (eq. 21 constants)' reached the target in "
            f"{int(eq21['reached_target'])} of {int(eq21['runs'])} runs, median "
            f"{epochs(e21)}"
            + (f" (slowest {slowest:g})" if np.isfinite(slowest) else "")
            + f", against {epochs(eb)} with the tuned constants and GA's {epochs(eg)}"
        )
        if not e21 < eg:
            tuned += ": with the paper's own constants BAS has no epoch advantage here."
        elif np.isfinite(eb) and eb > 0:
            tuned += (
                f": still ahead of GA, but by a factor {eg / e21:.2g} instead of {eg / eb:.2g}."
            )
        else:
            tuned += "."
    else:
        tuned += "; the full run shows this as the row 'BAS-RBFNN (eq. 21 constants)'."
    parts.append(tuned)
    if len(t4) > 2:
        parts.append(
            "Rows after the first two are variants the paper did not run: a harder start "
            f"(widths ×{cfg.narrow_width_factor:g}), eq. 21's printed constants, and the full "
            "encoding (centres, widths and weights all searched, the paper's description) "
            "from the RBFNN start and from a random start."
        )
    runs = res.tables["table4_runs"].copy()
    runs["model"] = runs["model"].astype(str)
    return [
        Table(
            "table4_ga_vs_bas",
            "Table 4. Comparison of GA-RBFNN and BAS-RBFNN",
            pd.DataFrame(rows),
            caption=" ".join(parts),
        ),
        Table(
            "table4_runs",
            "Table 4, run by run",
            runs.rename(
                columns={
                    "epochs_to_target": "epochs to target",
                    "epochs_run": "epochs run",
                    "initial_mse": "initial MSE",
                    "final_mse": "final MSE",
                    "mean_mNm": "mean [mN m]",
                    "max_mNm": "max [mN m]",
                }
            ),
            caption="Every run of Table 4 (not in the paper, which reports one run per "
            "method). A dash: the run did not reach the target MSE.",
        ),
    ]


def fig9_items(res, quick: bool) -> list:
    """[B] Fig. 9: the training MSE curves of GA-RBFNN and BAS-RBFNN (and every variant)."""
    cfg = res.config
    curves = res.curves
    main = {m: curves[m] for m in FIG9_MODELS if m in curves}
    runs = res.tables["table4_runs"]
    first = runs[runs["model"].isin(list(main))]["initial_mse"]
    start = float(np.nanmedian(first)) / cfg.target_mse
    png = fig9_png(res)
    caption = (
        f"Paper: {PAPER['figures']['fig9']} Ours: the best MSE so far after each epoch, "
        f"{cfg.seeds} runs per method (thin lines) and their median (thick), the target "
        "dashed, a triangle where a run reached it, and the paper's epoch dotted; epochs on a "
        "log scale, since ours are far fewer. Our runs "
        "start from the least-squares RBFNN network, already at about "
        f"{start:.2g} times the target MSE, so the curves start low and the search only "
        "closes the last gap; the paper's curves start far higher, presumably from random "
        "centres (it does not say). The epoch counts therefore measure different things; "
        "see Table 4 for why BAS's advantage depends on its tuned constants."
    )
    if quick:
        caption += (
            f" Quick run ({quick_setting(res)}): the target is out of reach "
            "there, so the curves show progress only."
        )
    items = [
        Figure(
            "fig9_training_mse",
            "Fig. 9. MSE curves of GA-RBFNN and BAS-RBFNN",
            png,
            caption=caption,
        )
    ]
    if len(curves) > len(main):
        items.append(
            Figure(
                "fig9_variants",
                "Fig. 9, all variants of Table 4",
                fig9_png(res, variants=True),
                caption="Not in the paper: the training MSE of each row of Table 4, drawn as "
                "Fig. 9 (one panel per variant, each with its own MSE axis).",
            )
        )
    return items
