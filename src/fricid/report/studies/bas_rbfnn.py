"""``fricid reproduce bas-rbfnn``: the BAS-RBFNN paper's tables and figures as a document.

[B] "An Optimized RBF Neural Network Based on Beetle Antennae Search Algorithm for Modeling the
Static Friction in a Robotic Manipulator Joint". Composes
:func:`fricid.experiments.bas_rbfnn_paper.run_bas_rbfnn`'s result: Fig. 1 (gravity fit,
eq. 7), Fig. 6 a-c (two-factor surfaces), Table 1 and Fig. 7 (the analytic models eq. 2-4),
Table 2 (parameters of eq. 4); the network sections (Table 3, Fig. 8, Table 4, Fig. 9,
Fig. 10) are :mod:`.bas_rbfnn_networks`'. Each table puts [B]'s numbers beside ours.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pandas as pd

from ...experiments.bas_rbfnn_paper import (
    STEPS,
    TABLE1_MODELS,
    BasRbfnnResult,
    run_bas_rbfnn,
)
from ...experiments.paper_numbers import BAS_RBFNN as PAPER
from ...experiments.paper_numbers import table1_rmse_unit
from ...fitted import FittedModel
from ...units import DEG
from .. import paper_plots as pp
from .. import plots
from ..document import Document, Figure, Note, Table
from .bas_rbfnn_networks import rbfnn_sections

__all__ = ["STEPS", "build_bas_rbfnn", "compose_bas_rbfnn"]


# -- Fig. 1 -------------------------------------------------------------------------------------


def _fig1(res: BasRbfnnResult) -> list:
    """[B] Fig. 1 and the gravity coefficients of eq. 7, the paper's beside ours."""
    theta, tau_g = res.gravity_points
    g = res.extraction.gravity
    paper = PAPER["gravity"]
    truth = res.true_gravity
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
    z = [(o - t) / se for o, t, se in zip((g.p_x, g.p_y), truth, (g.p_x_se, g.p_y_se), strict=True)]
    # the largest gap between our eq. 7 curve and the paper's over our positions
    gap = float(
        np.max(
            np.abs((g.p_x - paper["p_x"]) * np.cos(theta) - (g.p_y - paper["p_y"]) * np.sin(theta))
        )
    )
    built = bool(np.allclose(truth, (paper["p_x"], paper["p_y"])))
    lo, hi = PAPER["design"]["positions_deg"][:2]
    span = np.degrees([float(np.min(theta)), float(np.max(theta))])
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
                + (
                    "The virtual joint was built with the paper's p_x and p_y; "
                    if built
                    else "The virtual joint's p_x and p_y differ from the paper's; "
                )
                + f"our curve is at most {1e3 * gap:.2g} mN m from the paper's over our "
                f"positions ({span[0]:.0f} to {span[1]:.0f} deg; the paper's span {lo:g} to "
                f"{hi:g} deg)."
            ),
        ),
        Table(
            "fig1_gravity_coefficients",
            "Gravity coefficients of eq. 7",
            table,
            caption="The paper gives no uncertainty. Ours differs from the true values by "
            f"{z[0]:+.2g} (p_x) and {z[1]:+.2g} (p_y) standard errors.",
        ),
    ]


# -- Fig. 6 -------------------------------------------------------------------------------------


def _fig6(res: BasRbfnnResult) -> list:
    """[B] Fig. 6 a-c: friction against two factors, the third held."""
    g = res.grid
    if g is None:
        return [
            Note(
                "Fig. 6 needs a complete (temperature, velocity, position) grid of samples; "
                "the extraction lost some operating points.",
                kind="warning",
            )
        ]
    F, T, V, L = g["friction"], g["temperature"], g["velocity"] / DEG, g["load"]
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


def _table1(fits: dict[str, FittedModel], order_ok: bool) -> list:
    """[B] Table 1 and Fig. 7: the analytic models' indicators, the paper's beside ours."""
    paper = PAPER["table1"]
    rows = []
    for key, label, scale in (
        ("fitness", "Fitness (R²)", 1.0),
        ("rmse", "RMSE [mN m]", 1e3),
        ("rmspe", "RMSPE", 1.0),
    ):
        row: dict[str, Any] = {"indicator": label}
        for name in TABLE1_MODELS:
            row[f"{paper[name]['label']}: paper"] = paper[name][key]
            row[f"{paper[name]['label']}: ours"] = fits[name].metrics[key] * scale
        rows.append(row)
    ours = {n: fits[n].metrics for n in TABLE1_MODELS}
    labels = {n: paper[n]["label"] for n in TABLE1_MODELS}
    png = pp.indicator_bars(
        ours, paper, labels, title="Fig. 7: performance indicators of the identified models"
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
                "them). "
                + table1_rmse_unit()
                + " Ours is in mN m. "
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
    diffs = {n: ours[n]["fitness"] - paper[n]["fitness"] for n in TABLE1_MODELS}
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
    "v_tl0": 1 / DEG,
    "v_v0": 1 / DEG,
    "v_vT": 1 / DEG,
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
    """[B] Table 2: the velocity-load-temperature model's parameters (eq. 4)."""
    rows = []
    for name, (value, symbol) in PAPER["table2"].items():
        k = _PAPER_UNITS[name]
        ours = fitted.params[name]
        ci = fitted.parameters[name].ci95_halfwidth
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


# -- the whole paper ---------------------------------------------------------------------------


def compose_bas_rbfnn(res: BasRbfnnResult) -> Document:
    """The reproduction of [B] as a document.

    Parameters
    ----------
    res : fricid.experiments.bas_rbfnn_paper.BasRbfnnResult
        The computed study.

    Returns
    -------
    Document
        To be written with :func:`fricid.report.write_document`.
    """
    result, scenario = res.extraction, res.scenario
    samples, quick, seed = result.samples, res.quick, res.seed
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
    sec = doc.section("Fig. 1: gravity torque")
    for item in _fig1(res):
        sec.add(item)
    sec = doc.section("Fig. 6: friction against two factors")
    for item in _fig6(res):
        sec.add(item)
    fits = res.fits
    sec = doc.section("Table 1 and Fig. 7: the analytic models")
    for item in _table1(fits, res.claims["table1_fitness_rises"]):
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
    for title, text, items in rbfnn_sections(res):
        sec = doc.section(title, text)
        for item in items:
            sec.add(item)
    return doc


def build_bas_rbfnn(
    *, quick: bool = False, seed: int = 0, progress: Callable[[str], None] | None = None
) -> Document:
    """Run [B]'s study (:func:`~fricid.experiments.bas_rbfnn_paper.run_bas_rbfnn`, same
    parameters) and compose its document (:func:`compose_bas_rbfnn`)."""
    return compose_bas_rbfnn(run_bas_rbfnn(quick=quick, seed=seed, progress=progress))
