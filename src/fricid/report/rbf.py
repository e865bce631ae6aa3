"""The RBF network's part of a model report: predicted friction with bootstrap intervals over the
operating range, the network's structure, and its output weights (for an appendix).

An RBF network (BAS-RBFNN paper, eq. 14-15) has no small set of physical parameters whose
Jacobian CIs mean much, so the report gives a residual bootstrap instead: the hidden layer
(centres and widths) is held at its trained values, the residuals are resampled with
replacement, and the linear output layer (weights and bias) is re-solved by least squares for
each resample. That yields 95 % percentile intervals of the predicted friction over the
operating range (what a user of the model needs) and of the output weights (an appendix). It
is conditional on the hidden layer, so it understates the uncertainty of a network whose
centres were searched (BAS, GA).

The output is linear in every output weight and bias of every network the state holds (one,
or ``pos`` and ``neg`` for a ``per_direction`` state: :func:`fricid.models.rbf.sub_networks`),
sign of motion included, so each column of the design matrix is the model's own prediction
with that one coefficient set to 1 and all others to 0 (:func:`hidden_layer`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import pandas as pd

from ..fitted import FittedModel
from ..models import INPUTS, get_predictor
from ..models.hybrid import backbone_of
from ..models.rbf import (
    interval_half_width,
    magnitude_columns,
    sub_networks,
    tail_columns,
    tail_order,
)
from ..samples import FrictionSamples
from .band import held_at
from .document import Note, Table

__all__ = ["coefficient_names", "hidden_layer", "rbf_bootstrap", "rbf_parameter_items"]

#: Speeds per direction at which the report predicts friction with its interval.
N_SPEEDS = 8


def _slots(state: Mapping[str, Any]) -> list[tuple[str, str, int]]:
    """(side, "w", "b" or "a", index) of every output coefficient, side ``"all"`` for a
    single network: unit weights, the bias, the linear tail's coefficients."""
    out = []
    for side, net in sub_networks(state).items():
        out += [(side, "w", i) for i in range(len(net.get("weights") or ()))]
        if net.get("fit_bias", True) or net.get("linear") is not None:
            out.append((side, "b", -1))
        out += [(side, "a", i) for i in range(len(net.get("linear") or ()))]
    return out


def coefficient_names(state: Mapping[str, Any]) -> list[str]:
    """``w_1 .. w_m, bias`` (then ``a_<term>`` of a linear tail) for one network;
    ``pos w_1 .. pos bias, neg w_1 ..`` for two."""
    names = []
    for side, what, i in _slots(state):
        if what == "a":
            net = sub_networks(state)[side]
            base = f"a_{net['linear_terms'][i]}"
        else:
            base = f"w_{i + 1}" if what == "w" else "bias"
        names.append(base if side == "all" else f"{side} {base}")
    return names


def _tail_column(state: Mapping[str, Any], slot: tuple[str, str, int], X) -> np.ndarray:
    """The model's column of a linear-tail coefficient at ``X`` (sign of motion included)."""
    side, _, i = slot
    net = sub_networks(state)[side]
    Xa = np.asarray(X, dtype=float).copy()
    v = Xa[:, 0].copy()
    Xa[:, 0] = np.abs(v)
    names = list(net["inputs"])
    order = tail_order(names, net["linear_terms"]) or 1
    Xs = Xa[:, [INPUTS.index(n) for n in names]]
    col = tail_columns(Xs, magnitude_columns(names), order)[:, i]
    mask = {"all": np.ones(v.size, bool), "pos": v > 0, "neg": v < 0}[side]
    return np.where(mask, np.sign(v) * col, 0.0)


def _unit_state(state: Mapping[str, Any], slot: tuple[str, str, int]) -> dict[str, Any]:
    """``state`` with every output weight and bias 0, and no linear tail, except the one of
    ``slot`` (1)."""
    side, what, i = slot
    out = dict(state)
    for s, net in sub_networks(state).items():
        zero = {**net, "weights": [0.0] * len(net.get("weights") or ()), "bias": 0.0}
        zero.pop("linear", None)
        zero.pop("linear_terms", None)
        if s == "all":
            out.pop("linear", None)
            out.pop("linear_terms", None)
        if s == side:
            if what == "w":
                zero["weights"][i] = 1.0
            else:
                zero["bias"] = 1.0
        if s == "all":
            out.update(zero)
        else:
            out[s] = zero
    return out


def _coefficients(state: Mapping[str, Any]) -> np.ndarray:
    values = []
    for side, what, i in _slots(state):
        net = sub_networks(state)[side]
        if what == "a":
            values.append(float(net["linear"][i]))
        else:
            values.append(float(net["weights"][i]) if what == "w" else float(net.get("bias", 0.0)))
    return np.asarray(values)


def hidden_layer(fitted: FittedModel, X: np.ndarray) -> np.ndarray:
    """The design matrix ``A (n, k)`` of the stored network's output coefficients at ``X``.

    ``fitted.predict(X) == A @ c`` with ``c`` the coefficients named by
    :func:`coefficient_names` (every network's weights, then its bias where it has one);
    column j is the model's prediction with coefficient j set to 1 and all others to 0.
    """
    state = dict(fitted.state or {})
    model = get_predictor("rbf")
    cols = [
        _tail_column(state, slot, X)
        if slot[1] == "a"
        else model.predict(_unit_state(state, slot), X)
        for slot in _slots(state)
    ]
    return np.column_stack(cols) if cols else np.zeros((len(X), 0))


def rbf_bootstrap(
    fitted: FittedModel,
    samples: FrictionSamples,
    Xq: np.ndarray,
    *,
    n_boot: int = 200,
    seed: int = 0,
) -> dict[str, np.ndarray]:
    """Residual bootstrap of the output layer (see the module notes).

    Returns a dict with ``coefficients`` (n_boot, k) in the order of
    :func:`coefficient_names` and ``predictions`` (n_boot, len(Xq)).
    """
    rng = np.random.default_rng(seed)
    A = hidden_layer(fitted, samples.X)
    Aq = hidden_layer(fitted, Xq)
    y_hat = fitted.predict(samples.X, warn=False)
    resid = samples.friction - y_hat
    idx = rng.integers(0, resid.size, size=(n_boot, resid.size))
    Y = y_hat[None, :] + resid[idx]  # (n_boot, n)
    coef, *_ = np.linalg.lstsq(A, Y.T, rcond=None)  # (k, n_boot)
    coef = coef.T
    return {"coefficients": coef, "predictions": coef @ Aq.T}


def _query_points(fitted: FittedModel, samples: FrictionSamples) -> np.ndarray:
    """:data:`N_SPEEDS` speeds spread over the measured ones, on each side of motion the
    samples have (both for combined samples), at their median load and temperature."""
    speeds = np.abs(samples.velocity[samples.velocity != 0])
    if not speeds.size:
        speeds = np.abs(samples.velocity)
    pick = np.unique(np.quantile(speeds, np.linspace(0, 1, N_SPEEDS), method="nearest"))
    dirs = set(samples.directions())
    signs = [s for s in (-1.0, 1.0) if 0 in dirs or int(s) in dirs]
    v = np.concatenate([s * pick for s in signs])
    return np.column_stack(
        [
            v,
            np.full_like(v, np.median(samples.load)),
            np.full_like(v, np.median(samples.temperature)),
        ]
    )


def _residual_view(
    fitted: FittedModel, samples: FrictionSamples, Xq: np.ndarray
) -> tuple[FittedModel, FrictionSamples, np.ndarray | float]:
    """What the bootstrap resamples: the network itself, or for a hybrid model its residual
    network (an ``rbf`` model), the samples minus the backbone, and the backbone at ``Xq``
    (added back to the bootstrap's predictions)."""
    if fitted.model != "hybrid":
        return fitted, samples, 0.0
    from dataclasses import replace

    model, theta = backbone_of(fitted.state or {})
    view = FittedModel(
        model="rbf",
        optimizer=fitted.optimizer,
        operating_range=fitted.operating_range,
        provenance=fitted.provenance,
        state=dict((fitted.state or {})["residual"]),
    )
    rest = replace(samples, friction=samples.friction - model.predict(theta, samples.X))
    return view, rest, model.predict(theta, Xq)


def _facts(fitted: FittedModel) -> pd.DataFrame:
    state = fitted.state or {}
    rows: dict[str, Any] = {
        "symmetry": state.get("symmetry") or "signed",
        "trainer": fitted.optimizer.method,
    }
    if fitted.model == "hybrid":
        bb = state.get("backbone") or {}
        rows["analytic backbone"] = f"{bb.get('model')}: " + ", ".join(
            f"{k} = {float(v):.6g}" for k, v in dict(bb.get("params") or {}).items()
        )
        state = state.get("residual") or {}
    for side, net in sub_networks(state).items():
        tag = "" if side == "all" else f" ({side})"
        widths = np.asarray(net.get("widths", []), dtype=float)
        rows[f"inputs{tag}"] = ", ".join(net.get("inputs", []))
        rows[f"hidden units (centres){tag}"] = len(net.get("weights") or ())
        rows[f"velocity warp asinh(v / scale) [rad/s]{tag}"] = net.get("velocity_scale")
        rows[f"widths (standardised units){tag}"] = (
            f"{widths.min():.3g}–{widths.max():.3g}" if widths.size else "–"
        )
        rows[f"epochs run{tag}"] = net.get("n_epochs")
        rows[f"final training MSE (target scaled to [-1, 1]){tag}"] = net.get("train_mse_scaled")
        if net.get("linear") is not None:
            rows[f"linear tail{tag}"] = ", ".join(
                f"{t}: {float(a):.4g}"
                for t, a in zip(net["linear_terms"], net["linear"], strict=True)
            )
        sel = net.get("n_centers_selection")
        if isinstance(sel, Mapping) and sel.get("cv_rmse_chosen") is not None:
            rows[f"cross-validated RMSE [N m]{tag}"] = sel["cv_rmse_chosen"]
    return pd.DataFrame(
        {"property": list(rows), "value": [("–" if v is None else v) for v in rows.values()]}
    )


def rbf_parameter_items(
    fitted: FittedModel, samples: FrictionSamples, *, n_boot: int = 200, seed: int = 0
) -> tuple[list, list]:
    """The RBF network's report items: (main, appendix).

    Main: predicted friction with bootstrap 95 % intervals over the operating range and the
    network's structure; appendix: every output weight and bias with its interval.
    """
    Xq = _query_points(fitted, samples)
    view, vsamples, offset = _residual_view(fitted, samples, Xq)
    boot = rbf_bootstrap(view, vsamples, Xq, n_boot=n_boot, seed=seed)
    pred = fitted.predict(Xq, warn=False)
    lo_p, hi_p = np.percentile(boot["predictions"], [2.5, 97.5], axis=0) + offset
    half = interval_half_width(fitted.state, Xq, 0.9)
    table = {
        "velocity [rad/s]": Xq[:, 0],
        "load [N m]": Xq[:, 1],
        "temperature [°C]": Xq[:, 2],
        "predicted [N m]": pred,
        "95% CI low [N m]": lo_p,
        "95% CI high [N m]": hi_p,
    }
    note = ""
    if np.isfinite(half).any():
        table["90% prediction low [N m]"] = pred - half
        table["90% prediction high [N m]"] = pred + half
        note = (
            " The 90 % prediction interval (saved in the model file) covers a new averaged "
            "sample, noise included: conformal, from the cross-validation residuals of the "
            "network's structure selection. Those folds are random, so every velocity level "
            "was in training: the coverage holds at the measured velocity levels, not "
            "between or beyond them (there, see the leave-one-velocity-out error under "
            "'Can I trust this?')."
        )
    hybrid = fitted.model == "hybrid"
    held = held_at(fitted.inputs_used())
    main: list = [
        Table(
            "prediction_ci",
            "Predicted friction with bootstrap 95 % intervals over the operating range",
            pd.DataFrame(table),
            caption=(
                f"At {N_SPEEDS} speeds spread over the measured ones, on each side of motion"
                + (f", at {held} of the samples" if held else "")
                + f". Residual bootstrap, {n_boot} "
                "resamples, hidden layer held fixed (percentile intervals): it understates "
                "the uncertainty of searched centres"
                + (", and the backbone is held at its fit" if hybrid else "")
                + ". The weights are in the appendix."
                + note
            ),
        ),
        Table(
            "network",
            "The RBF network",
            _facts(fitted),
            caption="Gaussian hidden units (eq. 14) and a linear output layer (eq. 15).",
        ),
    ]
    coef = _coefficients(view.state or {})
    lo_w, hi_w = np.percentile(boot["coefficients"], [2.5, 97.5], axis=0)
    appendix: list = [
        Table(
            "parameters",
            "Output weights with bootstrap 95 % intervals",
            pd.DataFrame(
                {
                    "parameter": coefficient_names(view.state or {}),
                    "value": coef,
                    "unit": "N m",
                    "95% CI low": lo_w,
                    "95% CI high": hi_w,
                }
            ),
            caption=(
                f"Residual bootstrap, {n_boot} resamples, hidden layer held fixed. Individual "
                "weights of overlapping Gaussians are poorly determined; the predictions in "
                "the parameters section are what matters."
            ),
        ),
        Note(
            "Confidence intervals of an RBF network come from the bootstrap, not from a "
            "Jacobian: the network's parameters are many and strongly coupled."
        ),
    ]
    return main, appendix
