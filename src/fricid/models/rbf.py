"""The RBF neural network of the BAS-RBFNN paper (section 3.1) as mathematics: a network
stored as a plain, JSON-ready *state* and its prediction (eq. 14-15).

This is the models layer's part of the network (DESIGN.md, layer table): Gaussian hidden units
(eq. 14) and a linear output (eq. 15) with an optional bias, on inputs standardised as the
state records, and the checks that a stored state is well formed. Training the network (the
``lsq`` recipe, BAS-RBFNN and GA-RBFNN through :mod:`fricid.optim`) and the scikit-learn
estimator live in the identification layer, :mod:`fricid.identify.learned.rbf`; the numerical
kernels
(design matrices, least-squares output weights) in :mod:`fricid.models._rbf_core`.

A state (``FittedModel.state`` of a model ``"rbf"``) holds ``kind`` (``"gaussian_rbf"``),
``inputs`` (names among velocity, load, temperature), ``velocity_scale`` (None, or the asinh
warp of the first input), ``input_shift``, ``input_scale``, ``centers (m, d)``,
``widths (m,)``, ``weights (m,)`` and ``bias``, plus training notes that prediction ignores.

Friction opposes motion: ``symmetry`` says how the network gives the sign (issue 11, defect 1).

``"odd"``
    Combined samples (direction 0, eq. 11 of the BAS-RBFNN paper): the network is
    ``g(|v|, load, T)`` and the friction ``F = sign(v) g(|v|, load, T)`` (``F(0) = 0``).
``"pos"``, ``"neg"``
    Samples of one direction only: one network on ``|v|`` as for ``"odd"``; the other side
    is the mirror image, an extrapolation (``FittedModel.range_check`` says so).
``"per_direction"``
    Samples of both directions apart: ``state["pos"]`` and ``state["neg"]`` are two networks
    (each a state as above) on ``|v|``; ``F = +g_pos(|v|)`` for ``v > 0``, ``-g_neg(|v|)``
    for ``v < 0`` and 0 at ``v = 0``.
``"signed"``
    The network on signed velocity as given, with no sign of its own: what files written
    before the symmetry was recorded hold. ``FittedModel.from_dict`` reads such a file whose
    samples were combined (direction 0, hence ``v > 0`` only) as ``"odd"``, which is the model
    it was meant to be and repairs its sign at ``v < 0`` (:func:`legacy_symmetry`).

A state without the key is ``"signed"``.

Structure (issue 15): a network may carry a *linear tail*, coefficients ``state["linear"]``
of the columns ``state["linear_terms"]`` (:func:`tail_terms`: the raw SI inputs, velocity
unwarped, ``|v|`` under a sign-form symmetry, ``|load|``, then velocity times each other
input), added to
the output: ``g = sum_i w_i phi_i(z) + b + sum_j a_j x_j``. Far from the centres the Gaussians
vanish and ``g`` returns to ``b + a_L |load| + a_T T + (a_v + a_vL |load| + a_vT T) |v|``: a
Coulomb level and a viscous coefficient both linear in load and temperature, instead of
falling back to the bias. A network with a tail and a sign of its own (``SIGN_FORM``) floors
``g`` at ``state["magnitude_floor"]`` (half the smallest magnitude it fits on its training
data; 0 when absent): friction opposes motion, so a linear extrapolation far outside the data
(a load near zero, or of the other sign, from a narrow load range) cannot turn it into
propulsion or zero. ``state["state_version"]`` is 2 for states that may hold these (absent
or 1: the states of fricid before issue 15, which still load). The velocity warp
``asinh(|v| / velocity_scale)`` is logarithmic above ``velocity_scale`` (fit chooses it as the
smallest measured speed), so a decade of speed takes the same room in the network's input at
every speed.

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
from ._base import INPUTS, state_array

__all__ = [
    "NETWORK",
    "SIGN_FORM",
    "STATE_KIND",
    "STATE_VERSION",
    "SYMMETRIES",
    "RBFNetwork",
    "check_inputs",
    "interval_half_width",
    "legacy_symmetry",
    "magnitude_columns",
    "mse_z",
    "predict_state",
    "predict_z",
    "sub_networks",
    "symmetry_of",
    "tail_columns",
    "tail_order",
    "tail_terms",
]

#: ``state["kind"]`` of an RBF network in a model file.
STATE_KIND = "gaussian_rbf"

#: ``state["state_version"]`` fricid writes (2: the linear tail and prediction intervals of
#: issue 15 may be present; files without the key are version 1 and read as before).
STATE_VERSION = 2

#: ``state["symmetry"]`` values, with a line on each (module notes).
SYMMETRIES: dict[str, str] = {
    "odd": "F = sign(v) g(|v|, load, T), from combined samples (eq. 11)",
    "pos": "F = sign(v) g(|v|, load, T), identified for v > 0 only",
    "neg": "F = sign(v) g(|v|, load, T), identified for v < 0 only",
    "per_direction": "F = g_pos(|v|) for v > 0, -g_neg(|v|) for v < 0, two networks",
    "signed": "the network on signed velocity (files from before the symmetry was recorded)",
}

#: The symmetries whose friction is ``s(v) G(|v|, ...)`` with ``s = sign(v)``, so that tanh
#: smoothing can replace ``sign(v)`` (:mod:`fricid.models.smoothing`).
SIGN_FORM = ("odd", "pos", "neg", "per_direction")


def legacy_symmetry(directions) -> str:
    """The symmetry of a stored network without ``state["symmetry"]``.

    Parameters
    ----------
    directions : sequence of int or None
        ``provenance["directions"]`` of the model file.

    Returns
    -------
    str
        ``"odd"`` when the samples were combined only (``[0]``: trained on ``v > 0``, so
        ``sign(v) g(|v|)`` is the intended model and gives the right sign at ``v < 0``);
        else ``"signed"`` (the network as it was trained).
    """
    try:
        dirs = sorted({int(d) for d in directions or ()})
    except (TypeError, ValueError):
        return "signed"
    return "odd" if dirs == [0] else "signed"


def symmetry_of(state: Mapping[str, Any]) -> str:
    """``state["symmetry"]`` checked against :data:`SYMMETRIES` (``"signed"`` when absent).

    Raises
    ------
    DataError
        An unknown symmetry.
    """
    sym = state.get("symmetry") or "signed"
    if sym not in SYMMETRIES:
        raise DataError(
            f"unknown RBF symmetry {sym!r}; expected one of {', '.join(SYMMETRIES)}",
            column="state.symmetry",
        )
    return str(sym)


def sub_networks(state: Mapping[str, Any]) -> dict[str, Mapping[str, Any]]:
    """The networks of a state by side: ``{"pos": ..., "neg": ...}`` for ``per_direction``,
    else ``{"all": state}``.

    Raises
    ------
    DataError
        A ``per_direction`` state without its ``pos`` and ``neg`` objects.
    """
    if symmetry_of(state) != "per_direction":
        return {"all": state}
    nets = {}
    for side in ("pos", "neg"):
        sub = state.get(side)
        if not isinstance(sub, Mapping):
            raise DataError(
                f"a per-direction RBF state needs the network '{side}' (an object)",
                column=f"state.{side}",
            )
        nets[side] = sub
    return nets


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
    return state_array(state, key, shape, "RBF model", "state")


def _network(
    state: Mapping[str, Any], X: np.ndarray, where: str = "state", magnitude: bool = False
) -> np.ndarray:
    """One stored network's output at ``X (n, 3)`` (its inputs picked, warped, standardised);
    ``magnitude``: the output is ``g`` of a sign-form symmetry (floored at 0 with a linear
    tail)."""
    if state.get("kind", STATE_KIND) != STATE_KIND:
        raise DataError(
            f"unknown RBF state kind {state.get('kind')!r}; expected '{STATE_KIND}'",
            column=f"{where}.kind",
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
            column=f"{where}.inputs",
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
        raise DataError(
            "RBF model state has non-positive input scales or widths", column=f"{where}"
        )
    vscale = state.get("velocity_scale")
    Xs = X[:, [INPUTS.index(name) for name in inputs]]
    if vscale is not None:
        if inputs[0] != "velocity" or not float(vscale) > 0:
            raise DataError(
                "RBF model state 'velocity_scale' needs velocity as the first "
                "input and a positive value",
                column=f"{where}.velocity_scale",
            )
        Xs = Xs.copy()
        Xs[:, 0] = np.arcsinh(Xs[:, 0] / float(vscale))
    out = predict_z((Xs - shift) / scale, centers, widths, weights, bias)
    if state.get("linear") is not None:
        terms = state.get("linear_terms")
        order = tail_order(inputs, terms)
        if order is None:
            raise DataError(
                f"RBF model state 'linear_terms' must be {tail_terms(inputs)!r} or "
                f"{tail_terms(inputs, 2)!r} for inputs {list(inputs)!r}; got {terms!r}",
                column=f"{where}.linear_terms",
            )
        out = out + tail_columns(
            X[:, [INPUTS.index(n) for n in inputs]], magnitude_columns(inputs), order
        ) @ _state_array(state, "linear", (len(terms),))
        if magnitude:  # g is a magnitude: friction opposes motion
            floor = (
                float(_state_array(state, "magnitude_floor", ()))
                if (state.get("magnitude_floor") is not None)
                else 0.0
            )
            out = np.maximum(out, max(floor, 0.0))
    return out


def tail_terms(inputs: Sequence[str], order: int = 1) -> list[str]:
    """Names of the linear tail's columns for a network on ``inputs``: the inputs (the load
    as ``|load|``, :func:`tail_columns`), then the first (the velocity) times each other one,
    e.g. ``velocity*temperature`` (a viscous coefficient linear in load and temperature), and
    with ``order=2`` times each other one squared, ``velocity*temperature*temperature`` (a
    viscous coefficient quadratic in them: an Arrhenius-like coefficient to second order).
    Cross-validation chooses the order (:mod:`fricid.identify.learned._rbf_select`)."""
    names = list(inputs)
    first, others = names[0], names[1:]
    out = names + [f"{first}*{o}" for o in others]
    return out + [f"{first}*{o}*{o}" for o in others] if order == 2 else out


def tail_order(inputs: Sequence[str], terms) -> int | None:
    """The order (1 or 2) whose :func:`tail_terms` are ``terms``; None for neither."""
    for order in (1, 2):
        if terms == tail_terms(inputs, order):
            return order
    return None


def magnitude_columns(inputs: Sequence[str]) -> tuple[int, ...]:
    """Indices of the inputs the linear tail takes in magnitude: the load (friction grows
    with the magnitude of the load torque, Bittencourt and Gunnarsson 2012, so a load of the
    other sign, outside the data, extrapolates as its mirror image)."""
    return tuple(j for j, name in enumerate(inputs) if name == "load")


def tail_columns(Xs: np.ndarray, magnitude: Sequence[int] = (), order: int = 1) -> np.ndarray:
    """The linear tail's columns (:func:`tail_terms` of ``order``) of a network's raw inputs
    ``(n, d)``, the columns ``magnitude`` (:func:`magnitude_columns`) taken as absolute
    values."""
    Xs = np.array(Xs, dtype=float)
    for j in magnitude:
        Xs[:, j] = np.abs(Xs[:, j])
    v, d = Xs[:, 0], Xs.shape[1]
    cols = [Xs] + [v * Xs[:, j] for j in range(1, d)]
    if order == 2:
        cols += [v * Xs[:, j] ** 2 for j in range(1, d)]
    return np.column_stack(cols)


def predict_state(state: Mapping[str, Any] | None, X) -> np.ndarray:
    """Friction [N m] of a stored RBF network at ``X (n, 3)``: velocity [rad/s], load [N m],
    temperature [degC] (``FrictionSamples.X``); eq. 14-15, with the sign of motion as
    ``state["symmetry"]`` says (module notes).

    ``state`` is ``FittedModel.state`` as ``fricid.identify.learned.rbf.to_fitted_model`` writes it.

    Raises
    ------
    DataError
        A malformed state, or ``X`` without three columns.
    """
    if not isinstance(state, Mapping):
        raise DataError("an RBF model needs its network in 'state' (an object)")
    sym = symmetry_of(state)
    X = np.asarray(X, dtype=float)
    if X.ndim != 2 or X.shape[1] != len(INPUTS):
        raise DataError(
            f"inputs must have shape (n, 3): velocity, load, temperature; got {X.shape}"
        )
    if sym == "signed":
        return _network(state, X)
    v = X[:, 0]
    Xa = X.copy()
    Xa[:, 0] = np.abs(v)
    if sym != "per_direction":
        return np.sign(v) * _network(state, Xa, magnitude=True)
    nets = sub_networks(state)
    g_pos = _network(nets["pos"], Xa, "state.pos", magnitude=True)
    g_neg = _network(nets["neg"], Xa, "state.neg", magnitude=True)
    return np.where(v > 0, g_pos, np.where(v < 0, -g_neg, 0.0))


def interval_half_width(state: Mapping[str, Any] | None, X, level: float = 0.9) -> np.ndarray:
    """Half-width [N m] of the prediction interval at ``level`` stored with a learned model
    (``state["prediction_interval"]`` of each network: conformal quantiles of its
    cross-validation residuals, :func:`fricid.identify.learned._rbf_select.conformal_half_widths`),
    at each row of ``X (n, 3)``: the ``pos`` network's for ``v > 0`` and the ``neg`` one's
    for ``v < 0`` of a per-direction state; a hybrid model's are its residual network's.

    The interval of a prediction ``F(x)`` is ``F(x) -+ half_width``: it covers a new
    averaged sample at ``x`` (measurement noise included) with probability about ``level``
    inside the operating range; outside it says nothing.

    Returns
    -------
    ndarray, shape (n,)
        NaN where the state holds no interval at that level (files before issue 15).
    """
    X = np.asarray(X, dtype=float)
    out = np.full(X.shape[0], np.nan)
    if not isinstance(state, Mapping):
        return out
    if isinstance(state.get("residual"), Mapping):  # a hybrid model
        state = state["residual"]
    v = X[:, 0]
    try:
        nets = sub_networks(state)
    except DataError:
        return out
    for side, net in nets.items():
        pi = net.get("prediction_interval")
        if not isinstance(pi, Mapping):
            continue
        levels = [float(x) for x in pi.get("levels") or ()]
        widths = list(pi.get("half_width") or ())
        hits = [k for k, x in enumerate(levels) if abs(x - float(level)) < 1e-9]
        if not hits or hits[0] >= len(widths):
            continue
        mask = {"all": np.ones(v.size, bool), "pos": v > 0, "neg": v < 0}[side]
        out[mask] = float(widths[hits[0]])
    return out


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
        sym = st.get("symmetry") or "signed"
        if sym == "per_direction" and all(isinstance(st.get(k), Mapping) for k in ("pos", "neg")):
            return (
                f"two networks on |v|: v > 0 {_describe_net(st['pos'])}; v < 0 "
                f"{_describe_net(st['neg'])}; {SYMMETRIES[sym]}"
            )
        return _describe_net(st) + (f"; {SYMMETRIES[sym]}" if sym in SYMMETRIES else "")


def _describe_net(st: Mapping[str, Any]) -> str:
    return (
        f"{len(st.get('centers', []))} Gaussian units (eq. 14), linear output "
        f"(eq. 15){' with bias' if st.get('fit_bias') else ''}; inputs "
        f"{', '.join(st.get('inputs', []))}; trainer {st.get('trainer')}"
        + (f", encoding {st['encoding']}" if st.get("encoding") else "")
        + (f", {st['n_epochs']} epochs" if st.get("n_epochs") else "")
        + ("; linear tail on the raw inputs" if st.get("linear") is not None else "")
        + (
            f"; {st['n_centers_selection'].get('chosen')} centres chosen by "
            f"{st['n_centers_selection'].get('folds')}-fold cross-validation"
            + (
                " and whole speed levels held out"
                if st["n_centers_selection"].get("cv_folds") == "velocity_levels"
                else ""
            )
            if isinstance(st.get("n_centers_selection"), Mapping)
            else ""
        )
        + (
            "; dropped (constant): "
            + ", ".join(f"{k} = {v:.6g}" for k, v in st["dropped_inputs"].items())
            if isinstance(st.get("dropped_inputs"), Mapping) and st["dropped_inputs"]
            else ""
        )
    )


#: The one instance the model registry hands out.
NETWORK = RBFNetwork()
