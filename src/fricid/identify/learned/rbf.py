"""The RBF neural network friction model of the BAS-RBFNN paper (section 3) as a scikit-learn
regressor, its trainers, and its :class:`~fricid.fitted.FittedModel` (identification layer;
the network's mathematics, prediction from a stored state, lives in :mod:`fricid.models.rbf`).

:class:`RBFNetRegressor` is a three-layer network: Gaussian hidden units (eq. 14) and a linear
output (eq. 15) with an optional bias, on inputs that are standardised inside the estimator.
It is trained by one of

* ``trainer="lsq"``: k-means centres, the p-nearest-neighbour width rule and output weights by
  (ridge) linear least squares; the standard fast recipe and the paper's "RBFNN" (Table 3);
* ``trainer="bas"`` (BAS-RBFNN, eq. 18-21), ``"ga"`` (GA-RBFNN, Table 4, Fig. 9) or any other
  method of :data:`fricid.optim.METHODS`: the network's parameters are searched by
  :func:`fricid.optim.minimize`, minimising the training mean squared error (eq. 16-17, an
  :class:`~fricid.identify.problem.IdentificationProblem` with loss ``mse``), until a target
  MSE or the epoch budget (:mod:`fricid.identify.learned._rbf_search`). Two encodings of the search
  vector:

  - ``"full"``: centres, widths *and* output weights (and bias) are all searched, as the
    paper's section 3.3 describes ("BAS is used to optimize the network parameters");
  - ``"hybrid"``: centres and widths are searched; for every candidate the output weights are
    the ridge least-squares solution, computed for the whole candidate batch at once.

:func:`fricid.models.rbf.predict_state` evaluates a network stored in a
:class:`~fricid.fitted.FittedModel`'s ``state`` (plain lists, JSON-ready);
:func:`to_fitted_model` builds that model from a fitted estimator, and :func:`fit_rbf` does
both from :class:`~fricid.samples.FrictionSamples` (as ``fricid.identify.fit(samples, "rbf")``
does).

Friction opposes motion (issue 11, defect 1): :func:`fit_rbf` trains the network on ``|v|``
and stores it as ``F = sign(v) g(|v|, load, T)`` for combined samples (the paper's eq. 11 data,
``v > 0`` only, which a network on signed velocity extrapolated to the wrong sign at ``v < 0``),
one network per direction for samples of both directions, and one for a single direction
(``state["symmetry"]``, :mod:`fricid.models.rbf`). The estimator itself stays a plain
regressor on the ``X`` it is given, so the paper's study (``v > 0`` data) is unchanged.

The model file records what can be trusted (:func:`trust_records`,
:mod:`fricid.identify.learned._trust`): convergence (``lsq`` exact in closed form; an optimiser
trainer met its target or spent its budget), the effective degrees of freedom (the trace of
the ridge hat matrix, ESL eq. 3.50) behind the fit statistics, and the structure search's
cross-validation error as the ``validation``, labelled with what it tests.

Reading of the paper (where it is unclear, DESIGN.md "Faithful and honest")
--------------------------------------------------------------------------
* **Target MSE.** The paper trains to "MSE 0.0001" (section 4.3) and reports mean absolute
  errors of about 0.001 N m (Tables 3, 4). An MSE of 1e-4 N m^2 would be an RMSE of 10 mN m,
  ten times those errors, so the MSE cannot be in N m^2. We read it as the MSE of the target
  mapped linearly onto [-1, 1] (MATLAB's ``mapminmax``, the Neural Network Toolbox default):
  ``target_mse=1e-4`` then means an RMSE of 1 % of half the friction range. On the
  ``paper1`` virtual joint (friction 0.14-0.41 N m) that is 1.35 mN m RMSE, about 1.1 mN m
  mean absolute error: the paper's 0.0011 N m. ``mse_history_`` and ``target_mse`` use this
  scale; multiply by ``target_scale_ ** 2`` for N m^2.
* **Epoch.** The paper counts "epochs" of BAS and GA (Fig. 9) without defining them. Here one
  epoch is ``evals_per_epoch`` candidate evaluations (one candidate network scored on the
  whole training set is one evaluation): one generation of a GA whose population is
  ``evals_per_epoch`` plus its elites, and ``evals_per_epoch / 3`` iterations of fricid's
  default BAS (the position and both antennae), or ``evals_per_epoch / 2`` with the option
  ``evaluate_position=False`` that the BAS-RBFNN study uses (the two antennae of eq. 19, all
  eq. 18-21 need). So epochs compare the methods at equal cost.
* **Which encoding are the paper's figures?** Section 3.3 says BAS optimises "the weights and
  biases" of the network, and Fig. 3 puts the network's parameters in the beetle's position:
  the paper *describes* ``encoding="full"``. Its *results* (Table 3: BAS-RBFNN 2.6 times more
  accurate than RBFNN; Fig. 9: the target MSE reached within a few hundred epochs) are what
  the ``hybrid`` encoding achieves on our virtual joint, and not what ``full`` achieves: with
  80 centres (401 coordinates) the full encoding started from the ``lsq`` network never
  improved it in 300 epochs (its least-squares weights are large and cancel each other, so
  any step of the beetle in weight space makes the fit worse), and started at random it
  ended three orders of magnitude above the target (``fricid bench rbfnn``, Table 4). We
  therefore read the paper's figures as the hybrid encoding (or, equivalently, as BAS
  tuning centres and widths around a least-squares output layer).

References
----------
[B] "An Optimized RBF Neural Network Based on Beetle Antennae Search Algorithm for Modeling the
    Static Friction in a Robotic Manipulator Joint" (the BAS-RBFNN paper), eq. 14-21,
    Tables 3-4, Fig. 9-10.
[MD] J. Moody, C. J. Darken, "Fast learning in networks of locally-tuned processing units",
    Neural Computation 1(2), 1989 (k-means centres, p-nearest-neighbour widths).
"""

from __future__ import annotations

from collections.abc import Sequence
from numbers import Integral
from typing import Any

import numpy as np
from sklearn.utils.validation import check_is_fitted

from ...errors import ConfigError
from ...fitted import FittedModel, OptimizerRecord
from ...metrics import metrics
from ...models import INPUTS
from ...models.rbf import (
    STATE_KIND,
    STATE_VERSION,
    check_inputs,
    magnitude_columns,
    predict_state,
    tail_terms,
)
from ...samples import FrictionSamples
from .._records import operating_range, provenance
from .._scatter import measurement_scatter
from ._heldout import ERRORS, interval_record, take_errors
from ._rbf_estimator import LSQ_IGNORES, TRAINERS, RBFNetRegressor
from ._rbf_select import check_centres, choose_structure, drop_constant_inputs
from ._trust import (
    cv_pieces,
    cv_validation,
    hat_trace,
    learned_statistics,
    network_budget,
    network_convergence,
    side_states,
)

__all__ = [
    "LSQ_IGNORES",
    "TRAINERS",
    "RBFNetRegressor",
    "fit_rbf",
    "side_data",
    "symmetry_for",
    "to_fitted_model",
    "trust_records",
]


def _state(est: RBFNetRegressor, inputs: Sequence[str]) -> dict[str, Any]:
    linear = (
        {"linear_terms": tail_terms(inputs, int(est.tail_order)), "linear": est.linear_.tolist()}
        if est.linear_tail
        else {}
    )
    return {
        "kind": STATE_KIND,
        "state_version": STATE_VERSION,
        **linear,
        "inputs": list(inputs),
        "velocity_scale": None if est.velocity_scale is None else float(est.velocity_scale),
        "input_shift": est.input_shift_.tolist(),
        "input_scale": est.input_scale_.tolist(),
        "centers": est.centers_.tolist(),
        "widths": est.widths_.tolist(),
        "weights": est.weights_.tolist(),
        "bias": float(est.bias_),
        "fit_bias": bool(est.fit_bias),
        "trainer": str(est.trainer).lower(),
        "encoding": None if str(est.trainer).lower() == "lsq" else est.encoding,
        "n_epochs": int(est.n_epochs_),
        "epochs_to_target": est.epochs_to_target_,
        "target_mse": est.target_mse,
        "train_mse_scaled": float(est.train_mse_),
        "target_scale": float(est.target_scale_),
        "mse_history": est.mse_history_.tolist(),
    }


def _n_numbers(est: RBFNetRegressor) -> int:
    """Fitted numbers of a network (centres, widths, weights, bias, linear tail)."""
    return int(
        est.centers_.size
        + est.widths_.size
        + est.weights_.size
        + bool(est.fit_bias)
        + est.linear_.size
    )


def trust_records(
    ests: Sequence[RBFNetRegressor], state: dict[str, Any], samples: FrictionSamples
) -> tuple[dict[str, Any], float | None, str, dict[str, Any] | None]:
    """What a network's file records about its trust (:mod:`fricid.identify.learned._trust`):
    the convergence block, the effective degrees of freedom (None where undefined) with how
    they were counted, and the validation record of the structure search's cross-validation
    (None when it did not validate the trained network: an optimiser trainer, or no CV)."""
    sides = side_states(state)
    edfs = [s.get("edf") for s in sides]
    numbers = sum(_n_numbers(e) for e in ests)
    if all(isinstance(e, int | float) for e in edfs):
        edf: float | None = float(sum(edfs))
        parts = ["the output layer"]
        parts += ["the linear tail"] if ests[0].linear_tail else []
        parts += ["the bias"] if ests[0].fit_bias or ests[0].linear_tail else []
        how = (
            f"trace of the ridge hat matrix (ESL eq. 3.50) of {', '.join(parts)}, for a "
            f"network that stores {numbers} numbers"
        )
    else:
        edf = None
        how = (
            f"the centres and widths of the network ({numbers} numbers) were searched with "
            "the targets, so it is no linear smoother and its effective degrees of freedom "
            "are undefined"
            if str(ests[0].trainer).lower() != "lsq"
            else "the effective degrees of freedom were not recorded"
        )
    pieces = cv_pieces(state)
    lsq = str(ests[0].trainer).lower() == "lsq"
    validation = cv_validation(samples, pieces) if pieces and lsq else None
    return network_convergence(ests), edf, how, validation


def symmetry_for(samples: FrictionSamples) -> str:
    """The symmetry (:data:`fricid.models.rbf.SYMMETRIES`) a network of ``samples`` gets.

    ``"odd"`` for combined samples (direction 0), ``"per_direction"`` for both directions
    apart, ``"pos"`` / ``"neg"`` for one direction.

    Raises
    ------
    ConfigError
        Samples that mix combined and per-direction rows.
    """
    dirs = set(samples.directions())
    if dirs == {0}:
        return "odd"
    if 0 in dirs:
        raise ConfigError(
            "the samples mix combined (direction 0, eq. 11) and per-direction rows; fit the "
            "RBF network on one kind (fricid fit --direction combined, or both)"
        )
    return "per_direction" if dirs == {-1, 1} else ("pos" if dirs == {1} else "neg")


def side_data(samples: FrictionSamples) -> tuple[np.ndarray, np.ndarray]:
    """Inputs with ``|v|`` and the target ``s F`` (``s = -1`` where ``v < 0``, else 1): what a
    network with a sign of its own (``F = sign(v) g(|v|, ...)``) is trained on. For combined
    samples (``v > 0``) these are the samples as they are."""
    X = samples.X.copy()
    s = np.where(X[:, 0] < 0, -1.0, 1.0)
    X[:, 0] = np.abs(X[:, 0])
    return X, s * samples.y


def _history(ests: Sequence[RBFNetRegressor], n: int) -> list[list[float]] | None:
    """Per-epoch best SSE [N m^2] against evaluations, summed over the networks."""
    rows = []
    for est in ests:
        if not est.mse_history_.size:
            return None
        per_epoch = int(est.evals_per_epoch)
        evals = per_epoch * np.arange(1, est.mse_history_.size + 1)
        rows.append(np.column_stack([evals, est.mse_history_ * est.target_scale_**2 * n]))
    if not rows:
        return None
    k = max(len(r) for r in rows)
    padded = [np.vstack([r, np.repeat(r[-1:], k - len(r), axis=0)]) for r in rows]
    return np.sum(padded, axis=0).tolist()


def _model(
    ests: Sequence[RBFNetRegressor],
    state: dict[str, Any],
    samples: FrictionSamples,
    errors: np.ndarray | None = None,
) -> FittedModel:
    """The :class:`FittedModel` of trained networks whose state is ``state``; ``errors``
    [N m] the samples' held-out errors (the local spread of its intervals), if any."""
    X = samples.X
    y_hat = predict_state(state, X)
    est = ests[0]
    trainer = str(est.trainer).lower()
    n = len(samples)
    rs = est.random_state
    statuses = [e.status_ for e in ests]
    bad = [st for st in statuses if st not in (None, 0, 2)]
    status = bad[0] if bad else statuses[0]
    sides = ("v > 0", "v < 0") if len(ests) == 2 else ("",)
    message = "; ".join(
        f"{side}: {e.message_}" if side else e.message_
        for side, e in zip(sides, ests, strict=True)
        if e.message_
    )
    convergence, edf, how, validation = trust_records(ests, state, samples)
    statistics, note = learned_statistics(samples.y, y_hat, edf, how)
    scatter = measurement_scatter(samples)
    return FittedModel(
        model="rbf",
        prediction_interval=interval_record(errors, samples, scatter.value, HELD),
        metrics=metrics(samples.y, y_hat, samples.direction, scatter.value),
        statistics=statistics,
        statistics_note=note,
        convergence=convergence,
        validation=validation,
        loss={"scatter": scatter.to_dict()},
        optimizer=OptimizerRecord(
            method=trainer if trainer == "lsq" else f"{trainer}/{est.encoding}",
            seed=int(rs) if isinstance(rs, Integral) else None,
            status=status,
            message=message,
            nfev=int(sum(e.n_evals_ for e in ests)),
            max_evals=network_budget(ests),
            history=_history(ests, n),
        ),
        operating_range=operating_range(samples),
        provenance=provenance(
            samples,
            estimator="fricid.identify.learned.rbf.RBFNetRegressor",
            estimator_params={
                k: v
                for k, v in est.get_params().items()
                if k != "random_state" or isinstance(v, Integral | None)
            },
        ),
        state=state,
    )


def to_fitted_model(
    estimator: RBFNetRegressor,
    samples: FrictionSamples,
    inputs: Sequence[str] = INPUTS,
    *,
    symmetry: str | None = None,
) -> FittedModel:
    """A :class:`~fricid.fitted.FittedModel` (``model="rbf"``) of an estimator fitted on
    ``samples``, with metrics on ``samples`` and provenance as ``identify.fit`` records them;
    ``state`` holds the network as plain lists (see :func:`predict_state`).

    Parameters
    ----------
    estimator : RBFNetRegressor
        Fitted on the columns ``inputs`` of :func:`side_data` of ``samples`` (``|v|`` and
        ``sign(v) F``; for combined samples, ``v > 0``, that is ``samples.X`` and
        ``samples.y`` as they are).
    samples : FrictionSamples
        Its training samples.
    inputs : sequence of str
        The estimator's input columns, in order.
    symmetry : str, optional
        ``"odd"``, ``"pos"``, ``"neg"`` or ``"signed"`` (:data:`fricid.models.rbf.SYMMETRIES`;
        ``"signed"``: an estimator trained on signed velocity, with no sign of its own).
        Default: :func:`symmetry_for` the samples; both directions apart need two networks,
        which :func:`fit_rbf` trains.

    Returns
    -------
    FittedModel
        ``history`` is the per-epoch best SSE [N m^2] against evaluations, for optimiser
        trainers.
    """
    names = check_inputs(inputs)
    check_is_fitted(estimator)
    if estimator.n_features_in_ != len(names):
        raise ConfigError(
            f"the estimator was fitted on {estimator.n_features_in_} input "
            f"columns, but inputs names {len(names)}: {', '.join(names)}"
        )
    if estimator.velocity_scale is not None and names[0] != "velocity":
        raise ConfigError("velocity_scale warps the first input, which must be 'velocity'")
    symmetry = symmetry or symmetry_for(samples)
    if symmetry not in ("odd", "pos", "neg", "signed"):
        raise ConfigError(
            f"one estimator makes a network of symmetry odd, pos, neg or signed, not "
            f"{symmetry!r}; fit_rbf trains one network per direction"
        )
    state = {**_state(estimator, names), "symmetry": symmetry}
    return _model([estimator], state, samples)


def _train_side(
    samples: FrictionSamples, names: list[str], params: dict[str, Any], where: str
) -> tuple[RBFNetRegressor, dict[str, Any]]:
    """Train one network on ``samples`` (|v|, sign-corrected target): constant inputs
    dropped, the number of centres chosen by cross-validation when not given."""
    X, t = side_data(samples)
    X = X[:, [INPUTS.index(name) for name in names]]
    kept, dropped = drop_constant_inputs(X, names, where)
    X = X[:, [names.index(name) for name in kept]]
    params = dict(params)
    if "velocity" in dropped:
        params["velocity_scale"] = None
    notes: dict[str, Any] = {}
    if dropped:
        notes["dropped_inputs"] = dropped
    if "velocity_scale" not in params:  # the structured default: asinh warp of |v|
        params["velocity_scale"] = _default_velocity_scale(X) if kept[0] == "velocity" else None
    params.setdefault("linear_tail", True)
    if params["linear_tail"]:
        params.setdefault("linear_magnitude", magnitude_columns(kept))
    if params.get("velocity_scale") is not None and kept[0] != "velocity":
        raise ConfigError("velocity_scale warps the first input, which must be 'velocity'")
    if params.get("n_centers") is not None:
        check_centres(int(params["n_centers"]), len(t), where)
    level_folds = bool(params.pop("level_folds", True))
    chosen, note = choose_structure(
        X, t, {**params, "level_folds": level_folds}, speed_input=kept[0] == "velocity"
    )
    note["n_samples"] = len(t)
    errors = note.pop("heldout_errors", None)  # the local spread's, not the file's
    params.update({k: v for k, v in chosen.items() if params.get(k) is None})
    notes["n_centers_selection"] = note
    if "prediction_interval" in note:
        notes["prediction_interval"] = note["prediction_interval"]
    est = RBFNetRegressor(**params).fit(X, t)
    notes["edf"] = hat_trace(est, X)
    if est.linear_tail:  # the floor of the magnitude g (models.rbf notes)
        notes["magnitude_floor"] = 0.5 * max(float(np.min(est.predict(X))), 0.0)
    return est, {**_state(est, kept), **notes, ERRORS: errors}


#: What the local spread of a network's intervals is made of.
HELD = "cross-validation errors of the chosen structure (random folds)"


def _default_velocity_scale(X: np.ndarray) -> float | None:
    """The asinh warp's scale [rad/s]: the smallest measured speed, so that the warp is
    logarithmic over the measured speeds (a decade takes the same room everywhere)."""
    speeds = np.abs(X[:, 0])
    speeds = speeds[speeds > 0]
    return float(speeds.min()) if speeds.size else None


def fit_rbf(
    samples: FrictionSamples, inputs: Sequence[str] | None = None, **params: Any
) -> FittedModel:
    """Train the RBF network on ``samples`` and return it as a
    :class:`~fricid.fitted.FittedModel` (see :func:`to_fitted_model`).

    Friction opposes motion (issue 11, defect 1): the network learns ``g(|v|, load, T)``
    and predicts ``sign(v) g(|v|, ...)``. Combined samples (direction 0) give one network
    (symmetry ``"odd"``); samples of both directions give one network per direction
    (``"per_direction"``: ``+g_pos`` for ``v > 0``, ``-g_neg`` for ``v < 0``; seeds
    ``random_state`` and ``random_state + 1``, and half of ``max_epochs`` each, so that the
    budget is the fit's); one direction gives one network (``"pos"`` or
    ``"neg"``), whose other side is an extrapolation that ``FittedModel.predict`` warns about.
    :class:`RBFNetRegressor` itself is a plain regressor on whatever ``X`` it is given.

    Parameters
    ----------
    samples : FrictionSamples
        The data.
    inputs : sequence of str, optional
        The columns (any subset of velocity, load, temperature, in that order or another);
        default the measured ones (``samples.measured``).
        One that does not vary in the data is dropped with a
        :class:`~fricid.errors.DataQualityWarning` and noted in ``state["dropped_inputs"]``.
    **params
        :class:`RBFNetRegressor` parameters. The structured defaults (issue 15): a linear
        tail (``linear_tail=True``: far from the data the network returns to Coulomb plus
        viscous friction, linear in load and temperature), the asinh velocity warp at the
        smallest measured speed (``velocity_scale``), and the number of centres, width
        factor, velocity stretch and ridge penalty not given (or None) chosen by
        cross-validation of the ``lsq`` trainer over random folds and folds of whole interior
        speed levels (:mod:`fricid.identify.learned._rbf_folds`,
        :func:`fricid.identify.learned._rbf_select.choose_structure`;
        ``state["n_centers_selection"]``),
        whose held-out residuals give conformal prediction intervals
        (``state["prediction_interval"]``). A given number of centres above half the samples
        warns (:class:`~fricid.errors.IdentifiabilityWarning`).

    Returns
    -------
    FittedModel
        ``model="rbf"``, its network(s) in ``state``.
    """
    names = check_inputs(samples.measured if inputs is None else inputs)
    samples.require(names, "model 'rbf' (inputs=)")
    symmetry = symmetry_for(samples)
    if symmetry != "per_direction":
        est, state = _train_side(samples, names, params, "")
        errors = take_errors(samples, state, symmetry)
        return _model([est], {**state, "symmetry": symmetry}, samples, errors)
    ests, states = [], {}
    rs = params.get("random_state")
    shared = dict(params)
    if str(params.get("trainer", "lsq")).strip().lower() != "lsq":
        # one budget for the fit: each network gets half of the epochs
        epochs = int(params.get("max_epochs", LSQ_IGNORES["max_epochs"]))
        shared["max_epochs"] = max(1, -(-epochs // 2))
    for k, (side, d) in enumerate((("pos", 1), ("neg", -1))):
        side_params = dict(shared)
        if isinstance(rs, Integral):
            side_params["random_state"] = int(rs) + k
        where = f" for {'v > 0' if d > 0 else 'v < 0'}"
        est, states[side] = _train_side(
            samples.subset(samples.direction == d), names, side_params, where
        )
        ests.append(est)
    errors = take_errors(samples, states, "per_direction")
    first = states["pos"]
    state = {
        "kind": STATE_KIND,
        "symmetry": "per_direction",
        "inputs": names,
        "fit_bias": first["fit_bias"],
        "trainer": first["trainer"],
        "encoding": first["encoding"],
        **states,
    }
    return _model(ests, state, samples, errors)
