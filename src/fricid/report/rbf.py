"""The RBF network's part of a model report: its structure and bootstrap confidence intervals.

An RBF network (BAS-RBFNN paper, eq. 14-15) has no small set of physical parameters whose
Jacobian CIs mean much, so the report gives a residual bootstrap instead: the hidden layer
(centres and widths) is held at its trained values, the residuals are resampled with
replacement, and the linear output layer (weights and bias) is re-solved by least squares for
each resample. That yields 95 % percentile intervals of the output weights and of the
predicted friction at representative operating points. It is conditional on the hidden layer,
so it understates the uncertainty of a network whose centres were searched (BAS, GA).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..fitted import FittedModel
from ..samples import FrictionSamples
from .document import Note, Table

__all__ = ["hidden_layer", "rbf_bootstrap", "rbf_parameter_items"]


def hidden_layer(fitted: FittedModel, X: np.ndarray) -> np.ndarray:
    """The hidden-layer outputs ``Phi (n, m)`` of the stored network at inputs ``X (n, 3)``.

    The network is linear in its output weights, so column i is the prediction with weight
    vector e_i and zero bias (eq. 15); computed through the model's own ``predict``.
    """
    state = dict(fitted.state or {})
    m = len(state["weights"])
    cols = []
    for i in range(m):
        w = np.zeros(m)
        w[i] = 1.0
        cols.append(
            FittedModel(
                model="rbf", params={}, state={**state, "weights": w.tolist(), "bias": 0.0}
            ).predict(X)
        )
    return np.column_stack(cols)


def rbf_bootstrap(
    fitted: FittedModel,
    samples: FrictionSamples,
    Xq: np.ndarray,
    *,
    n_boot: int = 200,
    seed: int = 0,
) -> dict[str, np.ndarray]:
    """Residual bootstrap of the output layer (see the module notes).

    Returns a dict with ``weights`` (n_boot, m), ``bias`` (n_boot,) and ``predictions``
    (n_boot, len(Xq)).
    """
    rng = np.random.default_rng(seed)
    phi = hidden_layer(fitted, samples.X)
    phi_q = hidden_layer(fitted, Xq)
    fit_bias = bool((fitted.state or {}).get("fit_bias", True))
    A = np.column_stack([phi, np.ones(len(phi))]) if fit_bias else phi
    Aq = np.column_stack([phi_q, np.ones(len(phi_q))]) if fit_bias else phi_q
    y_hat = fitted.predict(samples.X)
    resid = samples.friction - y_hat
    idx = rng.integers(0, resid.size, size=(n_boot, resid.size))
    Y = y_hat[None, :] + resid[idx]  # (n_boot, n)
    coef, *_ = np.linalg.lstsq(A, Y.T, rcond=None)  # (m[+1], n_boot)
    coef = coef.T
    m = phi.shape[1]
    return {
        "weights": coef[:, :m],
        "bias": coef[:, m] if fit_bias else np.zeros(n_boot),
        "predictions": coef @ Aq.T,
    }


def _query_points(samples: FrictionSamples, n: int = 6) -> np.ndarray:
    speeds = np.unique(np.abs(samples.velocity))
    pick = np.unique(np.quantile(speeds, np.linspace(0, 1, n), method="nearest"))
    sign = 1.0 if (samples.velocity > 0).any() else -1.0
    return np.column_stack(
        [
            sign * pick,
            np.full_like(pick, np.median(samples.load)),
            np.full_like(pick, np.median(samples.temperature)),
        ]
    )


def rbf_parameter_items(
    fitted: FittedModel, samples: FrictionSamples, *, n_boot: int = 200, seed: int = 0
) -> list:
    """Tables for an RBF model: the network, its output weights with bootstrap 95 % CIs and
    predicted friction with bootstrap 95 % CIs at representative operating points."""
    state = fitted.state or {}
    widths = np.asarray(state.get("widths", []), dtype=float)
    facts = {
        "inputs": ", ".join(state.get("inputs", [])),
        "hidden units (centres)": len(state.get("weights", [])),
        "trainer": fitted.method,
        "velocity warp asinh(v / scale) [rad/s]": state.get("velocity_scale"),
        "widths (standardised units)": f"{widths.min():.3g}–{widths.max():.3g}"
        if widths.size
        else "–",
        "epochs run": state.get("n_epochs"),
        "epoch reaching the target MSE": state.get("epochs_to_target"),
        "target MSE (target scaled to [-1, 1])": state.get("target_mse"),
        "final training MSE (same scale)": state.get("train_mse_scaled"),
    }
    items: list = [
        Table(
            "network",
            "The RBF network",
            pd.DataFrame(
                {
                    "property": list(facts),
                    "value": [("–" if v is None else v) for v in facts.values()],
                }
            ),
            caption="Gaussian hidden units (eq. 14) and a linear output layer (eq. 15).",
        )
    ]
    Xq = _query_points(samples)
    boot = rbf_bootstrap(fitted, samples, Xq, n_boot=n_boot, seed=seed)
    weights = np.asarray(state.get("weights", []), dtype=float)
    lo_w, hi_w = np.percentile(boot["weights"], [2.5, 97.5], axis=0)
    rows = [
        {"parameter": f"w_{i + 1}", "value": w, "unit": "N m", "95% CI low": lo, "95% CI high": hi}
        for i, (w, lo, hi) in enumerate(zip(weights, lo_w, hi_w, strict=True))
    ]
    if state.get("fit_bias", True):
        lo_b, hi_b = np.percentile(boot["bias"], [2.5, 97.5])
        rows.append(
            {
                "parameter": "bias",
                "value": float(state.get("bias", 0.0)),
                "unit": "N m",
                "95% CI low": lo_b,
                "95% CI high": hi_b,
            }
        )
    items.append(
        Table(
            "parameters",
            "Output weights with bootstrap 95 % confidence intervals",
            pd.DataFrame(rows),
            caption=(
                f"Residual bootstrap, {n_boot} resamples, hidden layer held fixed "
                "(percentile intervals). Individual weights of overlapping Gaussians "
                "are poorly determined; the predictions below are what matters."
            ),
        )
    )
    pred = fitted.predict(Xq)
    lo_p, hi_p = np.percentile(boot["predictions"], [2.5, 97.5], axis=0)
    items.append(
        Table(
            "prediction_ci",
            "Predicted friction with bootstrap 95 % confidence intervals",
            pd.DataFrame(
                {
                    "velocity [rad/s]": Xq[:, 0],
                    "load [N m]": Xq[:, 1],
                    "temperature [°C]": Xq[:, 2],
                    "predicted [N m]": pred,
                    "95% CI low [N m]": lo_p,
                    "95% CI high [N m]": hi_p,
                    "± [N m]": 0.5 * (hi_p - lo_p),
                }
            ),
            caption="At speeds spread over the measured range, median load and "
            "temperature of the samples.",
        )
    )
    items.append(
        Note(
            "Confidence intervals of an RBF network come from the bootstrap above, "
            "not from a Jacobian: the network's parameters are many and strongly "
            "coupled."
        )
    )
    return items
