"""The BAS-RBFNN paper reproduced on the virtual joint: every table and figure, as a report.

Fig. 1 (gravity fit, eq. 7), Fig. 6 a-c (two-factor surfaces), Table 1 and Fig. 7 (the analytic
models eq. 2-4), Table 2 (parameters of the velocity-load-temperature model, eq. 4), Fig. 8 a-f
(predictions and errors of RBFNN, BAS-RBFNN and eq. 4), Table 3, Table 4, Fig. 9 (MSE curves of
GA and BAS) and Fig. 10 (errors in the unseen region). The network parts (Table 3, with
held-out k-fold errors and baselines beside the paper's training-set errors; Table 4 over
several seeds; Fig. 8-10) come from :func:`fricid.experiments.rbfnn_study.run_study`, run on the
samples simulated and extracted here; the rest is composed from the simulator, the extractor
and :func:`fricid.identify.fit`.
"""

from __future__ import annotations

import itertools
import logging
import math
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np
import pandas as pd

from ..extract import ExtractionResult, extract
from ..fitted import FittedModel
from ..identify import fit
from ..report import Document, Figure, Note, Table, plots
from ..report import paper_plots as pp
from ..sim import preset, simulate, true_gravity
from .paper_numbers import BAS_RBFNN as PAPER

__all__ = ["STEPS", "build_bas_rbfnn"]

logger = logging.getLogger(__name__)

#: Labels of the steps reported to the progress callback, in order.
STEPS = (
    "simulating and extracting the virtual joint (paper1 preset)",
    "Fig. 1: gravity fit",
    "Fig. 6: two-factor surfaces",
    "Table 1, Fig. 7, Table 2: analytic models",
    "Table 3, Fig. 8: RBF networks on all data and out of fold",
    "Table 4, Fig. 9: GA-RBFNN against BAS-RBFNN over several seeds",
    "Fig. 10: the unseen region; training times",
)

_TABLE1_MODELS = ("stribeck", "msk", "vlt")
_DEG = math.pi / 180.0


def _data(quick: bool, seed: int) -> tuple[ExtractionResult, Any]:
    scenario = preset("paper1", "reduced" if quick else "full")
    result = extract(simulate(scenario, seed=seed), **scenario.extract_options())
    samples = replace(result.samples, source=f"virtual joint paper1/{scenario.size}, seed {seed}")
    return replace(result, samples=samples), scenario


# -- Fig. 1 -------------------------------------------------------------------------------------


def _gravity_points(result: ExtractionResult) -> tuple[np.ndarray, np.ndarray]:
    """Per operating point: position [rad] and ``tau_g = -(tau+ + tau-)/2`` (eq. 11)."""
    bd = result.by_direction
    tau = bd.friction - bd.load  # the motor torque of each direction: tau_f - tau_g
    if len(bd) != 2 * len(result.samples):
        raise ValueError("expected both directions at every operating point")
    tau_minus, tau_plus = tau[0::2], tau[1::2]
    return result.position, -0.5 * (tau_plus + tau_minus)


def _fig1(result: ExtractionResult, scenario) -> list:
    theta, tau_g = _gravity_points(result)
    g = result.gravity
    paper = PAPER["gravity"]
    truth = true_gravity(scenario)
    fits = {"ours (least squares)": (g.p_x, g.p_y), "paper": (paper["p_x"], paper["p_y"])}
    png = pp.gravity_fit(theta, tau_g, fits, title="Fig. 1: gravity torque fitting curve")
    table = pd.DataFrame(
        {
            "coefficient": ["p_x [N m]", "p_y [N m]"],
            "paper": [paper["p_x"], paper["p_y"]],
            "ours": [g.p_x, g.p_y],
            "ours ± std. error": [g.p_x_se, g.p_y_se],
            "virtual joint (true)": list(truth),
        }
    )
    return [
        Figure(
            "fig1_gravity",
            "Fig. 1. Gravitational torque fitting curve",
            png,
            caption=(
                f"Paper: {PAPER['figures']['fig1']} Ours: the gravity torque of every operating "
                "point, separated from friction by the two directions (eq. 11), and eq. 7 "
                f"fitted by linear least squares ({g.n} points, residual RMS "
                f"{1e3 * g.residual_rms:.2g} mN m). "
                "The virtual joint was built with the paper's p_x and p_y, so the curves coincide; "
                "the paper's positions span -60 to -20 deg as ours."
            ),
        ),
        Table(
            "fig1_gravity_coefficients",
            "Gravity coefficients of eq. 7",
            table,
            caption="The paper gives no uncertainty. Ours recovers the true values within "
            "about two standard errors.",
        ),
    ]


# -- Fig. 6 -------------------------------------------------------------------------------------


def _grid(result: ExtractionResult, scenario) -> dict[str, np.ndarray] | None:
    """Samples as a (temperature, velocity, position bin) grid, or None if incomplete."""
    s = result.samples
    d = scenario.design
    nt, nv, nb = d.temperatures.size, d.velocities.size, d.positions.size
    if len(s) != nt * nv * nb:
        return None
    return {
        "friction": s.friction.reshape(nt, nv, nb),
        "load": s.load.reshape(nt, nv, nb).mean(axis=(0, 1)),
        "temperature": d.temperatures,
        "velocity": d.velocities,
    }


def _fig6(result: ExtractionResult, scenario) -> list:
    g = _grid(result, scenario)
    if g is None:
        return [
            Note(
                "Fig. 6 needs a complete (temperature, velocity, position) grid of samples; "
                "the extraction lost some operating points.",
                kind="warning",
            )
        ]
    F, T, V, L = g["friction"], g["temperature"], g["velocity"] / _DEG, g["load"]
    it = int(np.argmin(np.abs(T - 25.0)))
    ib = int(np.argmin(np.abs(L - np.median(L))))
    iv = int(np.argmin(np.abs(np.log(V) - np.log(6.0))))
    panels = [
        dict(
            x=V,
            y=L,
            z=F[it].T,
            xlog=True,
            xlabel="velocity [deg/s]",
            ylabel="load [N m]",
            title=f"(a) load and velocity, {T[it]:.0f} °C",
        ),
        dict(
            x=V,
            y=T,
            z=F[:, :, ib],
            xlog=True,
            xlabel="velocity [deg/s]",
            ylabel="temperature [°C]",
            title=f"(b) temperature and velocity, load {L[ib]:.3g} N m",
        ),
        dict(
            x=L,
            y=T,
            z=F[:, iv, :],
            xlabel="load [N m]",
            ylabel="temperature [°C]",
            title=f"(c) temperature and load, {V[iv]:.3g} deg/s",
            azim=-135,
        ),
    ]
    png = pp.surfaces(panels, title="Fig. 6: two combined factors dependence of friction")
    return [
        Figure(
            "fig6_surfaces",
            "Fig. 6 (a-c). Two combined factors dependence of friction",
            png,
            caption=(
                f"Paper: {PAPER['figures']['fig6']} Ours: the extracted friction samples "
                "of the virtual joint, the third factor held at the value named in each "
                "panel; velocity on a log axis. The same three trends appear: a Stribeck "
                "dip then viscous rise (a), friction falling with temperature (b) and "
                "rising with load (c). The virtual joint's law was chosen to show them, "
                "so this checks the simulator and the extraction, not the robot."
            ),
        )
    ]


# -- Table 1, Fig. 7, Table 2 -------------------------------------------------------------------


def _analytic_fits(samples, seed: int) -> dict[str, FittedModel]:
    return {name: fit(samples, name, "lm", seed=seed) for name in _TABLE1_MODELS}


def _table1(fits: dict[str, FittedModel]) -> list:
    paper = PAPER["table1"]
    rows = []
    for key, label, scale in (
        ("fitness", "Fitness (R²)", 1.0),
        ("rmse", "RMSE [mN m]", 1e3),
        ("rmspe", "RMSPE", 1.0),
    ):
        row: dict[str, Any] = {"indicator": label}
        for name in _TABLE1_MODELS:
            row[f"{paper[name]['label']}: paper"] = paper[name][key]
            row[f"{paper[name]['label']}: ours"] = fits[name].metrics[key] * scale
        rows.append(row)
    ours = {n: fits[n].metrics for n in _TABLE1_MODELS}
    labels = {n: paper[n]["label"] for n in _TABLE1_MODELS}
    png = pp.indicator_bars(
        ours, paper, labels, title="Fig. 7: performance indicators of the identified models"
    )
    order_ok = all(
        ours[a]["fitness"] < ours[b]["fitness"] for a, b in itertools.pairwise(_TABLE1_MODELS)
    )
    return [
        Table(
            "table1_analytic_models",
            "Table 1. Performance indicators for the models",
            pd.DataFrame(rows),
            caption=(
                "Velocity = Stribeck model (eq. 2), velocity-load = Msk (eq. 3), "
                "velocity-temperature-load = eq. 4, each fitted to all samples by "
                "Levenberg-Marquardt least squares (the paper does not say how it fitted "
                "them). The paper states no unit for RMSE; its values match mN m (its "
                "velocity-temperature-load RMSE 6.1 is close to its Table 3 mean error of "
                "5.8 mN m), so ours is in mN m. "
                + (
                    "As in the paper, fitness rises and errors fall as load and then "
                    "temperature enter the model. "
                    if order_ok
                    else "Unlike the paper, the fitness does not rise monotonically. "
                )
                + _fitness_remark(ours, paper)
            ),
        ),
        Figure(
            "fig7_indicators",
            "Fig. 7. Performance indicators for the identified models",
            png,
            caption=(
                f"Paper: {PAPER['figures']['fig7']} Ours beside the paper's, each indicator "
                "divided by its largest value over the three models (the paper plots "
                "normalised values without saying how it normalised)."
            ),
        ),
    ]


def _fitness_remark(ours: dict, paper: dict) -> str:
    """Say how our fitness compares with the paper's, model by model (Table 1)."""
    diffs = {n: ours[n]["fitness"] - paper[n]["fitness"] for n in _TABLE1_MODELS}
    parts = [f"{paper[n]['label']} {d:+.3f}" for n, d in diffs.items()]
    return (
        "Our fitness minus the paper's: " + ", ".join(parts) + ". The differences come from "
        "the joints, not the method: the virtual joint's law (not of the form of eq. 2-4) "
        "sets how much the simpler models miss, and its noise is about 0.5 mN m; the paper's "
        "real joint has effects no model here describes."
    )


_PAPER_UNITS = {
    "f_c": 1e3,
    "f_ctl": 1.0,
    "f_stl": 1.0,
    "f_v0": 1e3,
    "f_vT": 1e3,
    "v_tl0": 1 / _DEG,
    "v_v0": 1 / _DEG,
    "v_vT": 1 / _DEG,
}
_PAPER_UNIT_NAMES = {
    "f_c": "mN m",
    "f_ctl": "1",
    "f_stl": "1",
    "f_v0": "mN m",
    "f_vT": "mN m/°C",
    "v_tl0": "deg/s",
    "v_v0": "deg/s",
    "v_vT": "deg/s/°C",
}


def _table2(fitted: FittedModel) -> list:
    rows = []
    for name, (value, symbol) in PAPER["table2"].items():
        k = _PAPER_UNITS[name]
        ours = fitted.params[name]
        ci = fitted.ci95.get(name, np.nan)
        rows.append(
            {
                "parameter": symbol,
                "fricid name": name,
                "paper": value,
                "ours (paper's units)": ours * k,
                "ours 95% CI ±": ci * k,
                "unit (paper's, as read)": _PAPER_UNIT_NAMES[name],
                "ours (SI)": ours,
                "SI unit": fitted.units.get(name, ""),
            }
        )
    return [
        Table(
            "table2_vlt_parameters",
            "Table 2. The parameters of the velocity-load-temperature model",
            pd.DataFrame(rows),
            caption=(
                "Eq. 4 is garbled in print; fricid reads it as documented in "
                "fricid.models.VelocityLoadTemperature. The paper gives no units; its "
                "magnitudes fit torques in mN m and velocities in deg/s, so ours are shown "
                "that way too (and in SI). The values differ because the joints differ: "
                "ours is the virtual joint (its true law is not of the form of eq. 4, so "
                "there are no true values to recover), the paper's a SIASUN SR4C joint 2. "
                "Compare magnitudes and signs, not digits."
            ),
        )
    ]


# -- the RBF network study (Tables 3-4, Fig. 8-10) ---------------------------------------------

#: Table 3's rows of the paper's three models: the study's label -> key of the paper's numbers.
_T3_PAPER = {"RBFNN": "rbfnn", "BAS-RBFNN": "bas_rbfnn", "VLT model": "vlt"}
_VLT_LABEL = "Velocity-load-temperature model (eq. 4)"
#: The study's labels of Table 4's two methods -> key of the paper's numbers.
_T4_PAPER = {"GA-RBFNN": "ga_rbfnn", "BAS-RBFNN": "bas_rbfnn"}


def _label(study_label: str) -> str:
    return _VLT_LABEL if study_label == "VLT model" else study_label


def _study_data(samples, scenario) -> tuple[Any, np.ndarray, float]:
    """The study's ``data``: the samples, the virtual joint's true friction at their rows and
    the noise floor [N m], as :func:`fricid.experiments.rbfnn_study.paper1_data` makes them,
    without simulating the joint a second time."""
    from ..sim import expected_noise_std, true_samples

    truth = true_samples(scenario)
    floor = float(np.sqrt(np.mean(expected_noise_std(scenario) ** 2)))
    if len(samples) == len(truth) and np.allclose(
        samples.velocity, truth.velocity, rtol=0.05, atol=1e-3
    ):
        return samples, truth.friction.copy(), floor
    law = scenario.joint.law  # rows not on the design's grid: evaluate the law at the samples
    v, load, temp = samples.velocity, samples.load, samples.temperature
    return samples, 0.5 * (law(v, load, temp) - law(-v, load, temp)), floor


def _study_progress(say: Callable[[str], None]) -> Callable[[str], None]:
    """Log the study's own progress lines; its Table 4 and timing stages start steps 6 and 7
    of :data:`STEPS`."""
    pending = [("Table 4", STEPS[5]), ("timing", STEPS[6])]

    def on(message: str) -> None:
        logger.info("RBF study: %s", message)
        if pending and message.startswith(pending[0][0]):
            say(pending.pop(0)[1])

    return on


def _run_study(samples, scenario, *, quick: bool, seed: int, say: Callable[[str], None]):
    from . import rbfnn_study

    cfg = rbfnn_study.study_config(quick, seed=seed, timing_repeats=1)
    data = _study_data(samples, scenario)
    return rbfnn_study.run_study(cfg, data=data, progress=_study_progress(say))


def _mnm(value: float) -> str:
    return f"{value:.3g} mN m"


def _epochs(value: float) -> str:
    return f"{value:g} epochs" if np.isfinite(value) else "not reached"


def _quick_setting(res) -> str:
    cfg = res.config
    n = int(res.tables["data"]["samples"].iloc[0])
    return f"{n} samples, {cfg.n_centers} centres, at most {cfg.max_epochs} epochs"


def _study_note(res, quick: bool) -> Note:
    cfg = res.config
    d = res.tables["data"].iloc[0]
    lines = [
        "The networks come from fricid.experiments.rbfnn_study (the study behind "
        "`fricid bench rbfnn`), run on the samples above"
        + (
            " with its quick settings (reduced design, smaller networks and budgets; "
            "not the paper's settings)."
            if quick
            else " with its full settings."
        ),
        "",
        f"- {cfg.n_centers} Gaussian centres (k-means, widths {cfg.width_factor:g} × the "
        f"nearest-neighbour distance); {cfg.folds}-fold cross-validation; {cfg.seeds} seeds "
        f"per method in Table 4, up to {cfg.max_epochs} epochs each.",
        f"- Noise of the virtual joint's samples: {_mnm(d['noise_floor_mNm'])} RMS (the "
        f"samples differ from the true friction by {_mnm(d['rms_samples_minus_truth_mNm'])} "
        "RMS).",
    ]
    lines += [f"- {n}" for n in res.notes if not n.startswith("Timings")]
    return Note("\n".join(lines))


def _table3(res, quick: bool) -> list:
    t3 = res.tables["table3"]
    k = res.config.folds
    floor = float(res.tables["data"]["noise_floor_mNm"].iloc[0])
    paper = PAPER["table3"]
    cv_mean = f"ours, {k}-fold held-out: mean [mN m]"
    rows = []
    for _, r in t3.iterrows():
        key = _T3_PAPER.get(r["model"])
        p = paper[key] if key else {}
        rows.append(
            {
                "model": _label(r["model"]),
                "setup": r["setup"] + ("" if key else "; not in the paper's Table 3"),
                "paper: mean [mN m]": 1e3 * p.get("mean", np.nan),
                "ours, all data: mean [mN m]": r["all_mean_mNm"],
                "paper: max [mN m]": 1e3 * p.get("max", np.nan),
                "ours, all data: max [mN m]": r["all_max_mNm"],
                cv_mean: r["cv_mean_mNm"],
                f"ours, {k}-fold held-out: max [mN m]": r["cv_max_mNm"],
                "ours, held-out RMSE to the true friction [mN m]": r["cv_rmse_truth_mNm"],
            }
        )
    by = t3.set_index("model")
    rb, bas, vlt = (by.loc[m] for m in ("RBFNN", "BAS-RBFNN", "VLT model"))
    if bas["all_mean_mNm"] < rb["all_mean_mNm"] < vlt["all_mean_mNm"]:
        order = (
            "As in the paper, on all data BAS-RBFNN's mean error is below RBFNN's and both "
            "below eq. 4's "
        )
    else:
        order = "Unlike the paper (BAS-RBFNN < RBFNN < eq. 4), on all data the mean errors are "
    order += (
        f"({bas['all_mean_mNm']:.3g}, {rb['all_mean_mNm']:.3g} and {vlt['all_mean_mNm']:.3g} "
        "mN m; the paper's 1.1, 2.9 and 5.8). "
    )
    if bas["cv_mean_mNm"] < rb["cv_mean_mNm"]:
        held = (
            f"Held out, BAS-RBFNN keeps its lead over RBFNN ({bas['cv_mean_mNm']:.3g} against "
            f"{rb['cv_mean_mNm']:.3g} mN m), so it is not only fitting the training noise. "
        )
    else:
        held = (
            f"Held out, BAS-RBFNN loses its lead ({bas['cv_mean_mNm']:.3g} against RBFNN's "
            f"{rb['cv_mean_mNm']:.3g} mN m): on all data it was fitting noise. "
        )
    truth = by["cv_rmse_truth_mNm"]
    rbf = truth[[m for m in truth.index if "RBFNN" in m]]
    best = str(truth.idxmin())
    if best == "GP":
        base = (
            "The paper compares the networks only with its own eq. 4. scikit-learn's Gaussian "
            "process, a baseline it did not run, beats every RBF network here: held-out "
            f"RMSE to the true friction {truth['GP']:.3g} mN m against {rbf.min():.3g} for "
            f"the best network ({rbf.idxmin()}); the default MLP reaches "
            f"{truth.get('MLP', np.nan):.3g}. "
        )
    else:
        base = (
            f"Of all models, {_label(best)} is closest to the true friction held out "
            f"({truth[best]:.3g} mN m; the Gaussian process {truth.get('GP', np.nan):.3g}, "
            f"the best RBF network {rbf.min():.3g}). "
        )
    caption = (
        "Absolute error between predicted and measured friction. 'All data': trained and "
        f"tested on all {int(res.tables['data']['samples'].iloc[0])} samples, as the paper "
        f"(its Table 3 is of the training set); '{k}-fold held-out': each sample predicted "
        "by a model that did not see it, which the paper does not report; the last column "
        "compares the held-out predictions with the virtual joint's true friction, which "
        "only a simulator knows. The paper's errors, in N m, are shown in mN m. Rows after "
        "the paper's three are baselines it did not run. "
        + order
        + held
        + base
        + f"The measurement noise is about {floor:.3g} mN m RMS: a held-out error against "
        "the measured friction cannot fall far below it, and an all-data error well below it "
        "means the model follows the noise. Absolute errors are not comparable with the "
        "paper's (a real SR4C joint against the virtual one); the ordering is. "
        "'RBFNN, plain inputs' uses the paper's input scaling (standardised, no velocity "
        "warp): the Stribeck dip at low speed is then too narrow for the Gaussians."
    )
    if quick:
        caption += f" Quick run: {_quick_setting(res)}, not the paper's settings."
    return [
        Table(
            "table3_prediction_errors",
            "Table 3. Comparison of prediction effects",
            pd.DataFrame(rows),
            caption=caption,
        )
    ]


def _fig8(res) -> list:
    pred = res.predictions
    models = {"RBFNN": "RBFNN", "BAS-RBFNN": "BAS-RBFNN", "VLT model": "eq. 4 model"}
    png = pp.prediction_panels(
        pred["measured"],
        {name: pred[label] for label, name in models.items()},
        title="Fig. 8: predicted and measured friction, and the errors (all data as training)",
        letters="abcdef",
    )
    err = {label: 1e3 * float(np.mean(np.abs(pred["measured"] - pred[label]))) for label in models}
    gp = ""
    if "GP" in pred:
        gp_err = 1e3 * float(np.mean(np.abs(pred["measured"] - pred["GP"])))
        gp = f" The Gaussian process (not in the paper, not drawn) has {gp_err:.3g} mN m."
    n = len(pred["measured"])
    return [
        Figure(
            "fig8_predictions",
            "Fig. 8 (a-f). Predicted and practical static friction, and prediction errors",
            png,
            caption=(
                f"Paper: {PAPER['figures']['fig8']} Ours: the three models trained on all "
                f"{n} samples (Table 3's 'all data' columns), predicted at the same samples, "
                "ordered by temperature, then velocity, then position: each short ramp is "
                "one position sweep (friction rising with the gravity load), a run of ramps "
                "one temperature. "
                "Our mean errors: RBFNN "
                f"{err['RBFNN']:.3g}, BAS-RBFNN {err['BAS-RBFNN']:.3g}, eq. 4 "
                f"{err['VLT model']:.3g} mN m (the paper: 2.9, 1.1, 5.8)."
                + gp
                + " The error panels share one scale. Eq. 4's errors are larger and "
                "structured (the virtual joint's law is not of its form); the networks' are "
                "smaller and less structured."
            ),
        )
    ]


def _table4(res, quick: bool) -> list:
    t4 = res.tables["table4"]
    cfg = res.config
    paper = PAPER["table4"]
    rows = []
    for _, r in t4.iterrows():
        key = _T4_PAPER.get(r["model"])
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
                f" (quick settings: {_quick_setting(res)}): Table 4 "
                "compares the final MSE and errors only; run without --quick for epochs."
                if quick
                else f" within {cfg.max_epochs} epochs."
            )
        )
    else:
        eb, eg = float(bas["epochs_median"]), float(ga["epochs_median"])
        verdict = (
            "BAS-RBFNN needs fewer epochs than GA-RBFNN, as in the paper"
            if eb < eg
            else "Unlike the paper, BAS-RBFNN does not need fewer epochs than GA-RBFNN"
        )
        parts.append(
            f"{verdict}: median {_epochs(eb)} against {_epochs(eg)} (reached in {reached_b} and "
            f"{reached_g} of {cfg.seeds} runs; the paper's 257 against 356, one run each)."
        )
    eq21 = (
        by.loc["BAS-RBFNN (eq. 21 constants)"]
        if "BAS-RBFNN (eq. 21 constants)" in by.index
        else None
    )
    from .rbfnn_study import BAS_PAPER

    ours, printed = cfg.bas_options, BAS_PAPER
    floor_ours = ours["d_inc"] / (1.0 - ours["eta_d"])
    floor_paper = printed["d_inc"] / (1.0 - printed["eta_d"])
    tuned = (
        "How large BAS's advantage is depends on its constants: ours uses eq. 21's form with "
        f"constants tuned on this preset (antenna floor {floor_ours:g} instead of "
        f"{floor_paper:g}, step decay {ours['eta_step']:g} instead of "
        f"{printed['eta_step']:g} per iteration; GA's mutation index tuned likewise). With "
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
            f"{_epochs(e21)}"
            + (f" (slowest {slowest:g})" if np.isfinite(slowest) else "")
            + f", against {_epochs(eb)} with the tuned constants and GA's {_epochs(eg)}"
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


def _fig9(res, quick: bool) -> list:
    cfg = res.config
    curves = res.curves
    main = {m: curves[m] for m in ("GA-RBFNN", "BAS-RBFNN") if m in curves}
    paper_epochs = {m: PAPER["fig9"]["epochs"][_T4_PAPER[m]] for m in main}
    runs = res.tables["table4_runs"]
    first = runs[runs["model"].isin(list(main))]["initial_mse"]
    start = float(np.nanmedian(first)) / cfg.target_mse
    png = pp.mse_curves(
        main,
        cfg.target_mse,
        paper_epochs=paper_epochs,
        title="Fig. 9: training MSE of GA-RBFNN and BAS-RBFNN",
        ncols=2,
        log_epochs=True,
    )
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
            f" Quick run ({_quick_setting(res)}): the target is out of reach "
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
                pp.mse_curves(
                    curves,
                    cfg.target_mse,
                    title="Training MSE of every Table 4 variant",
                    ncols=4,
                    sharey=False,
                ),
                caption="Not in the paper: the training MSE of each row of Table 4, drawn as "
                "Fig. 9 (one panel per variant, each with its own MSE axis).",
            )
        )
    return items


def _fig10(res) -> list:
    f10 = res.tables["fig10"].set_index("model")
    unseen = res.unseen
    paper = PAPER["fig10"]
    rows = []
    for label, r in f10.iterrows():
        is_bas = label == "BAS-RBFNN"
        rows.append(
            {
                "model": _label(str(label)) + ("" if is_bas else " (not in the paper's Fig. 10)"),
                "paper: mean [mN m]": 1e3 * paper["mean"] if is_bas else np.nan,
                "ours: mean [mN m]": r["mean_mNm"],
                "paper: max [mN m]": 1e3 * paper["max"] if is_bas else np.nan,
                "ours: max [mN m]": r["max_mNm"],
                "ours: mean at 45 °C [mN m]": r["mean_at_45C_mNm"],
                "ours: mean at 47-55 °C [mN m]": r["mean_47_55C_mNm"],
            }
        )
    bas = f10.loc["BAS-RBFNN"]
    best = str(f10["mean_mNm"].idxmin())
    at45, beyond = float(bas["mean_at_45C_mNm"]), float(bas["mean_47_55C_mNm"])
    if beyond > at45:
        where = (
            f"Most of BAS-RBFNN's error comes from extrapolating in temperature: "
            f"{at45:.3g} mN m at 45 °C (inside the training temperatures; velocity and "
            f"position extrapolated only) against {beyond:.3g} mN m at 47-55 °C, beyond the "
            "training data's 45 °C."
        )
    else:
        where = (
            f"BAS-RBFNN's error is {at45:.3g} mN m at 45 °C (velocity and position "
            f"extrapolated) and {beyond:.3g} mN m at 47-55 °C (temperature extrapolated too)."
        )
    ratios = f10["mean_47_55C_mNm"] / f10["mean_at_45C_mNm"]
    caption = (
        f"Paper: {PAPER['figures']['fig10']} Ours: each model trained on all data (as Table "
        "3), evaluated against the virtual joint's true friction at the paper's unseen "
        f"points ({len(unseen['truth'])}: 52-60 deg/s, -22 to -10 deg, 45-55 °C, steps of 2). "
        f"BAS-RBFNN: mean {bas['mean_mNm']:.3g}, maximum {bas['max_mNm']:.3g} mN m (the "
        "paper: 1.2 and 6.3). "
        + where
        + " The paper's training data end at 45 °C and 50 deg/s too, so its Fig. 10 is an "
        "extrapolation as well; a Gaussian network falls back to its bias away from its "
        "centres, so how far it holds depends on the widths, and the paper's low error there "
        "is not a property the method guarantees. "
        f"The best model out there is {_label(best)} ({f10.loc[best, 'mean_mNm']:.3g} mN m)"
        + {
            "VLT model": ": a physical law extrapolates where the networks do not.",
            "GP": ", a baseline the paper did not run: its fitted length-scales are long "
            "enough in temperature and velocity to carry the trend past the data.",
        }.get(best, ".")
        + " Error growth from 45 °C to 47-55 °C, by model: "
        + ", ".join(f"{_label(str(m))} ×{v:.2g}" for m, v in ratios.items() if np.isfinite(v))
        + "."
    )
    drawn = {_label(m): unseen[m] for m in f10.index if m in unseen and m != "RBFNN, plain inputs"}
    png = pp.unseen_region(
        unseen["temperature"],
        drawn,
        title="Fig. 10: prediction errors beyond the experimental area",
        highlight="BAS-RBFNN",
        train_max_temperature=45.0,
        paper={"mean": paper["mean"], "max": paper["max"]},
    )
    return [
        Table(
            "fig10_unseen_errors",
            "Fig. 10 in numbers: absolute errors in the unseen region",
            pd.DataFrame(rows),
            caption="Mean and maximum absolute error against the true friction; the paper "
            "reports BAS-RBFNN's only (in N m, shown in mN m). 'RBFNN, plain inputs' is in "
            "the table but not drawn (its errors are far larger).",
        ),
        Figure(
            "fig10_unseen",
            "Fig. 10. Prediction errors in the unseen region",
            png,
            caption=caption,
        ),
    ]


def _rbfnn_sections(samples, scenario, *, quick: bool, seed: int, say: Callable[[str], None]):
    """Tables 3-4 and Fig. 8-10 from :mod:`fricid.experiments.rbfnn_study`, as
    (section title, text, items)."""
    res = _run_study(samples, scenario, quick=quick, seed=seed, say=say)
    return [
        (
            "Table 3 and Fig. 8: RBFNN, BAS-RBFNN and eq. 4",
            "Section 4.2 of the paper: an RBF network trained by least squares (RBFNN), "
            "one whose centres and widths are searched by BAS (BAS-RBFNN), and the analytic "
            "eq. 4, compared on the data they were trained on.",
            [_study_note(res, quick), *_table3(res, quick), *_fig8(res)],
        ),
        (
            "Table 4 and Fig. 9: GA-RBFNN against BAS-RBFNN",
            "Section 4.3: the same network optimised by a genetic algorithm and by BAS, "
            "epochs to the target MSE and the MSE curves.",
            [*_table4(res, quick), *_fig9(res, quick)],
        ),
        (
            "Fig. 10: the unseen region",
            "Section 4.4: the networks asked about operating points outside the experiment.",
            _fig10(res),
        ),
    ]


# -- the whole paper ---------------------------------------------------------------------------


def build_bas_rbfnn(
    *, quick: bool = False, seed: int = 0, progress: Callable[[str], None] | None = None
) -> Document:
    """Reproduce the BAS-RBFNN paper on the virtual joint.

    Parameters
    ----------
    quick : the reduced ``paper1`` design (330 samples) and the RBF study's quick settings
        (:func:`~fricid.experiments.rbfnn_study.study_config`), for tests; otherwise the
        paper's full design (21 positions, 15 velocities, 21 temperatures) and the study's
        full settings (with Table 4's variants; about 6 minutes on 2 cores).
    seed : seeds the simulator and every stochastic step.
    progress : called with the label of each step of :data:`STEPS` as it starts.

    Returns
    -------
    Document, to be written with :func:`fricid.report.write_document`.
    """
    say = progress or (lambda _label: None)
    say(STEPS[0])
    result, scenario = _data(quick, seed)
    samples = result.samples
    doc = Document(
        title=f"Reproduction: {PAPER['short']}",
        summary=(
            f"“{PAPER['title']}”, every table and figure regenerated on fricid's virtual "
            "joint (the paper's data are not public). Each table puts the paper's published "
            "numbers beside ours; each figure's caption says what the paper showed and why "
            "ours differs where it does."
        ),
        meta={
            "virtual joint": f"paper1 preset, {scenario.size} design",
            "samples": f"{len(samples)} (temperature × velocity × position bin)",
            "seed": seed,
            "mode": "quick (reduced design and budgets)" if quick else "full",
        },
    )
    sec = doc.section(
        "The data",
        "The paper's experiment (section 2) run on the virtual joint: "
        "bidirectional constant-velocity sweeps, median filtering, averaging over "
        "repetitions, and the two directions separating friction from gravity "
        "(eq. 9-11).\n\n" + scenario.description,
    )
    sec.add(Note("Extraction: " + result.summary().replace("\n", "; ")))
    say(STEPS[1])
    sec = doc.section("Fig. 1: gravity torque")
    for item in _fig1(result, scenario):
        sec.add(item)
    say(STEPS[2])
    sec = doc.section("Fig. 6: friction against two factors")
    for item in _fig6(result, scenario):
        sec.add(item)
    say(STEPS[3])
    fits = _analytic_fits(samples, seed)
    sec = doc.section("Table 1 and Fig. 7: the analytic models")
    for item in _table1(fits):
        sec.add(item)
    sec = doc.section("Table 2: the velocity-load-temperature model")
    for item in _table2(fits["vlt"]):
        sec.add(item)
    sec.add(
        Figure(
            "table2_vlt_curves",
            "The velocity-load-temperature model over the samples",
            plots.friction_curves(
                samples,
                fits["vlt"].predict,
                velocity_unit="deg/s",
                title="Eq. 4 with the parameters of Table 2 (ours)",
            ),
            caption="Not a figure of the paper: the identified eq. 4 model drawn over "
            "the samples, one curve per temperature (colour) and load band (panel), to "
            "show where it fits and where it misses.",
        )
    )
    say(STEPS[4])
    for title, text, items in _rbfnn_sections(samples, scenario, quick=quick, seed=seed, say=say):
        sec = doc.section(title, text)
        for item in items:
            sec.add(item)
    return doc
