"""The RBF neural network of the BAS-RBFNN paper (section 3.1) as mathematics: a network
stored as a plain, JSON-ready *state* and its prediction (eq. 14-15).

This is the models layer's part of the network (DESIGN.md, layer table): Gaussian hidden units
(eq. 14) and a linear output (eq. 15) with an optional bias, on inputs standardised as the
state records, and the checks that a stored state is well formed. Training the network (the
``lsq`` recipe, BAS-RBFNN and GA-RBFNN through :mod:`fricid.optim`) and the scikit-learn
estimator live in the identification layer, :mod:`fricid.identify.rbf`; the numerical kernels
(design matrices, least-squares output weights) in :mod:`fricid.models._rbf_core`.

A state (``FittedModel.state`` of a model ``"rbf"``) holds ``kind`` (``"gaussian_rbf"``),
``inputs`` (names among velocity, load, temperature), ``velocity_scale`` (None, or the asinh
warp of the first input), ``input_shift``, ``input_scale``, ``centers (m, d)``,
``widths (m,)``, ``weights (m,)`` and ``bias``, plus training notes that prediction ignores.

References
----------
[B] "An Optimized RBF Neural Network Based on Beetle Antennae Search Algorithm for Modeling the
    Static Friction in a Robotic Manipulator Joint" (the BAS-RBFNN paper), eq. 14-15.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import numpy as np

from ..errors import ConfigError, DataError
from . import _rbf_core as core
from ._base import INPUTS

__all__ = [
    "NETWORK",
    "STATE_KIND",
    "RBFNetwork",
    "check_inputs",
    "mse_z",
    "predict_state",
    "predict_z",
]

#: ``state["kind"]`` of an RBF network in a model file.
STATE_KIND = "gaussian_rbf"


def predict_z(Z: np.ndarray, C: np.ndarray, s: np.ndarray, w: np.ndarray, b: float) -> np.ndarray:
    """Network output (eq. 14-15) for standardised inputs ``Z (n, d)``.

    Parameters
    ----------
    Z : ndarray, shape (n, d)
        Standardised inputs.
    C : ndarray, shape (m, d)
        Centres.
    s : ndarray, shape (m,)
        Widths.
    w : ndarray, shape (m,)
        Output weights.
    b : float
        Output bias.

    Returns
    -------
    ndarray, shape (n,)
        The output, computed in row blocks so the design matrix stays small.
    """
    n, m = Z.shape[0], C.shape[0]
    rows = max(1, core.CHUNK_ELEMENTS // max(1, m))
    if n <= rows:
        return core.output(core.design(Z, C, s), w, b)
    return np.concatenate(
        [core.output(core.design(Z[i : i + rows], C, s), w, b) for i in range(0, n, rows)]
    )


def mse_z(
    Z: np.ndarray, t: np.ndarray, C: np.ndarray, s: np.ndarray, w: np.ndarray, b: float
) -> float:
    """Mean squared error of one network against targets ``t (n,)`` at standardised ``Z``."""
    r = predict_z(Z, C, s, w, b) - t
    return float(r @ r) / r.size


def check_inputs(inputs: Sequence[str]) -> list[str]:
    """The input names, stripped and lower-cased.

    Raises
    ------
    ConfigError
        Unless they are distinct names among velocity, load and temperature.
    """
    names = [str(name).strip().lower() for name in inputs]
    if not names or any(n not in INPUTS for n in names) or len(set(names)) != len(names):
        raise ConfigError(
            f"inputs must be distinct names among {', '.join(INPUTS)}; got {list(inputs)!r}"
        )
    return names


def _state_array(state: Mapping[str, Any], key: str, shape: tuple[int | None, ...]) -> np.ndarray:
    if key not in state:
        raise DataError(f"RBF model state lacks '{key}'", column=f"state.{key}")
    try:
        arr = np.asarray(state[key], dtype=float)
    except (TypeError, ValueError):
        raise DataError(f"RBF model state '{key}' is not numeric", column=f"state.{key}") from None
    if arr.ndim != len(shape) or any(
        want is not None and got != want for got, want in zip(arr.shape, shape, strict=True)
    ):
        raise DataError(
            f"RBF model state '{key}' has shape {arr.shape}, expected "
            f"{tuple('*' if s is None else s for s in shape)}",
            column=f"state.{key}",
        )
    if not np.isfinite(arr).all():
        raise DataError(f"RBF model state '{key}' has non-finite values", column=f"state.{key}")
    return arr


def predict_state(state: Mapping[str, Any] | None, X) -> np.ndarray:
    """Friction [N m] of a stored RBF network at ``X (n, 3)``: velocity [rad/s], load [N m],
    temperature [degC] (``FrictionSamples.X``); eq. 14-15.

    ``state`` is ``FittedModel.state`` as ``fricid.identify.rbf.to_fitted_model`` writes it.

    Raises
    ------
    DataError
        A malformed state, or ``X`` without three columns.
    """
    if not isinstance(state, Mapping):
        raise DataError("an RBF model needs its network in 'state' (an object)")
    if state.get("kind", STATE_KIND) != STATE_KIND:
        raise DataError(
            f"unknown RBF state kind {state.get('kind')!r}; expected '{STATE_KIND}'",
            column="state.kind",
        )
    inputs = state.get("inputs")
    if (
        not isinstance(inputs, Sequence)
        or isinstance(inputs, str)
        or not inputs
        or any(name not in INPUTS for name in inputs)
        or len(set(inputs)) != len(inputs)
    ):
        raise DataError(
            f"RBF model state 'inputs' must be distinct names among "
            f"{', '.join(INPUTS)}; got {inputs!r}",
            column="state.inputs",
        )
    d = len(inputs)
    shift = _state_array(state, "input_shift", (d,))
    scale = _state_array(state, "input_scale", (d,))
    centers = _state_array(state, "centers", (None, d))
    m = centers.shape[0]
    widths = _state_array(state, "widths", (m,))
    weights = _state_array(state, "weights", (m,))
    bias = float(_state_array(state, "bias", ()))
    if (scale <= 0).any() or (widths <= 0).any():
        raise DataError("RBF model state has non-positive input scales or widths", column="state")
    vscale = state.get("velocity_scale")
    X = np.asarray(X, dtype=float)
    if X.ndim != 2 or X.shape[1] != len(INPUTS):
        raise DataError(
            f"inputs must have shape (n, 3): velocity, load, temperature; got {X.shape}"
        )
    Xs = X[:, [INPUTS.index(name) for name in inputs]]
    if vscale is not None:
        if inputs[0] != "velocity" or not float(vscale) > 0:
            raise DataError(
                "RBF model state 'velocity_scale' needs velocity as the first "
                "input and a positive value",
                column="state.velocity_scale",
            )
        Xs = Xs.copy()
        Xs[:, 0] = np.arcsinh(Xs[:, 0] / float(vscale))
    return predict_z((Xs - shift) / scale, centers, widths, weights, bias)


class RBFNetwork:
    """The RBF network as a registered model (:func:`fricid.models.get_predictor`).

    Like the analytic models it predicts with ``predict(theta_or_state, X)``; its "parameters"
    are a state (see the module notes), so ``stateful`` is True and a
    :class:`~fricid.fitted.FittedModel` hands it ``state`` instead of a parameter vector.
    """

    name: ClassVar[str] = "rbf"
    title: ClassVar[str] = "RBF neural network"
    equation: ClassVar[str] = "BAS-RBFNN paper eq. 14-15"
    stateful: ClassVar[bool] = True

    def predict(self, state: Mapping[str, Any] | None, X) -> np.ndarray:
        """Friction [N m] at ``X (n, 3)``; see :func:`predict_state`."""
        return predict_state(state, X)

    def describe(self, state: Mapping[str, Any] | None) -> str:
        """One line on a stored network, for fit reports."""
        st = dict(state or {})
        return (
            f"{len(st.get('centers', []))} Gaussian units (eq. 14), linear output "
            f"(eq. 15){' with bias' if st.get('fit_bias') else ''}; inputs "
            f"{', '.join(st.get('inputs', []))}; trainer {st.get('trainer')}"
            + (f", encoding {st['encoding']}" if st.get("encoding") else "")
            + (f", {st['n_epochs']} epochs" if st.get("n_epochs") else "")
        )


#: The one instance the model registry hands out.
NETWORK = RBFNetwork()
