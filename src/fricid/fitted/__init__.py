"""``FittedModel``: an identified friction model with its metrics, uncertainty and provenance.

It is what ``identify.fit`` returns and what the JSON model file holds; reports, exports and
``fricid predict`` start from it. Each parameter is one record (:class:`Parameter`, after
lmfit's: value, unit, fixed, start, bounds, standard error, 95 % interval and its open ends,
flags), and how the optimum was found is one record too (:class:`OptimizerRecord`). The JSON
is plain (numbers, strings, lists), versioned by ``schema_version`` (files of version 1, with
the parameters spread over one object per field, are read through
:func:`fricid.fitted._migrate.upgrade`), SI units throughout. Prediction is dispatched by model
(:func:`fricid.models.get_predictor`): analytic models take the parameter vector, the RBF
network its stored ``state``. :meth:`FittedModel.report` prints a fit report after lmfit's
``fit_report`` from what the file stores.

A model file may come from a stranger, so loading is strict (issue 12): the file is read by
:func:`fricid.io._jsonfile.read_json` (at most 64 MiB, UTF-8, nesting at most 64 deep, no
NaN, Infinity or overflowing numbers, no repeated keys), checked against the JSON Schema
(finite numbers, bounded sizes, identifier names, the RBF network's typed arrays), and
:meth:`FittedModel.from_dict` refuses parameters outside their family's valid region
(``fricid.models.Parameter.region``), ranges whose minimum exceeds their maximum and a model
that cannot be evaluated, or predicts a non-finite friction, on its operating range. Every
failure is one :class:`~fricid.errors.DataError` line naming the file given.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from os import PathLike
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from .. import __version__
from ..errors import ConfigError, DataError, ExtrapolationWarning, FricidError, user_stacklevel
from ..io._jsonfile import check_document, one_line, read_json
from ..models import INPUTS, get_model, get_predictor
from ..models._range import RANGE_TOLERANCE, RangeViolation, range_violations
from ..models.rbf import legacy_symmetry
from ._file import SCHEMA_VERSION, _clean, _downsample, _num, _probe_inputs, _validate_schema
from ._interval import PredictionInterval, prediction_interval
from ._migrate import upgrade
from ._parameter import OptimizerRecord, Parameter, is_not_determined, parameters_from_values
from ._report import MIN_CORREL, fit_report

__all__ = [
    "MIN_CORREL",
    "RANGE_TOLERANCE",
    "SCHEMA_VERSION",
    "FittedModel",
    "OptimizerRecord",
    "Parameter",
    "PredictionInterval",
    "RangeViolation",
    "is_not_determined",
]


def _check_region(model, theta, field_name: str, name: str, source: str | None) -> None:
    """A :class:`DataError` naming the file and the first parameter of ``theta`` outside the
    valid region its family declares (``fricid.models.Parameter.region``)."""
    bad = model.region_violation(theta)
    if bad is not None:
        param, value = bad
        raise DataError(
            f"field '{field_name}/{param.name}/value': {value!r} lies outside model "
            f"'{name}''s valid region ({param.rule}, the {param.description})",
            file=source,
        )


@dataclass
class FittedModel:
    """An identified model.

    Attributes
    ----------
    model : registry name of the model (``fricid.models.MODELS``, ``*_asym``, or ``"rbf"``).
    parameters : one :class:`Parameter` per parameter, fixed ones included, in the model's
        order (empty for the learned models): value, unit, fixed, start, search bounds,
        standard error, 95 % interval with its open ends, the note saying why there is no
        interval, and the flags at bound, not determined, at initial value. The standard
        error comes from the Jacobian at the optimum (``cov = s^2 (J^T J)^+``, an SVD
        pseudo-inverse as scipy's ``curve_fit``, ``s^2 = SSE / (n - p)``); NaN where not
        determined, and for every parameter of a fit that did not converge or whose optimum
        is degenerate (the note says why). The interval's ends lie inside the search box
        (profile likelihood, or the linearised interval ``t(0.975, n - p) * stderr`` cut at
        the box: ``ci_method``). ``params``, ``units``, ``fixed``, ``free`` and ``at_bound``
        are read-only views of these records.
    ci_method : ``"profile"``, ``"jacobian"``, ``"cluster-robust"`` (trajectories) or ``""``
        (no intervals).
    correlation : correlation matrix of the free parameters (list of lists, rows in the order
        of ``free``), or None.
    optimizer : the optimiser's record (:class:`OptimizerRecord`): method, seed, status and
        message (why it stopped: ``fricid.optim.OptimizeResult.status``), evaluations, budget
        and the history of (evaluations, best SSE) pairs.
    convergence : the verdict on convergence (``fricid.identify.static.convergence.certify``):
        ``converged``, ``polish_sse_ratio``, ``polish_nfev``, ``certified_by`` and, when not
        converged, ``reason`` and ``advice``; None when not recorded.
    metrics : fit metrics on the identification data (``fricid.metrics.metrics``).
    statistics : fit statistics after lmfit: ``ndata``, ``nvarys``, ``nfree``, ``chisqr``
        (the SSE), ``redchi``, ``aic``, ``bic``, ``rsquared``
        (:func:`fricid.metrics.fit_statistics`); for the learned models ``nvarys_effective``
        and ``nfree_effective`` (the effective degrees of freedom, the trace of the hat
        matrix) in place of ``nvarys`` and ``nfree``, or neither and no AIC, BIC or reduced
        chi-square where they are undefined (:mod:`fricid.identify.learned._trust`).
    statistics_note : how the statistics count the model's degrees of freedom, or why some
        are not given ("" for an analytic fit: its free parameters).
    operating_range : min and max of velocity, load and temperature in the data.
    provenance : data source, sample count, fricid version, creation time.
    state : model-specific arrays for non-analytic models (the RBF network).
    loss : how the fit weighed its residuals: ``loss`` (l2, soft_l1, huber), ``f_scale``
        [N m] of a robust loss, ``weights`` (none, std, given) and the measurement
        ``scatter`` (value [N m], method, caveat; :mod:`fricid.identify.validate`).
    validation : held-out validation (:func:`fricid.identify.validate.validate`): scheme,
        held-out RMSE, scatter, ratio, verdict, folds; None when not validated.
    selection : ``fit(samples, "auto")``'s comparison of candidate models
        (:mod:`fricid.identify.static.select`): the table, the choice and why; None otherwise.
    prediction_interval : what an analytic model's prediction intervals need (the delta
        method: ``free``, their ``covariance``, ``noise_std`` [N m], ``dof``, and ``scale``,
        the multiplier calibrated at levels 0.9 and 0.95; :mod:`fricid.fitted._interval`);
        None for the learned models (their intervals are in ``state``) and files from
        before it was stored.
    trust : the trust verdict and where each of its numbers came from
        (:class:`fricid.identify.trust.Trust`, ``to_dict()``), with what it was computed on
        (samples and model hashes, options); None when not assessed. ``fricid fit`` and the
        fleet store it; ``fricid report`` reuses it only for the same samples and options.
    """

    model: str
    parameters: dict[str, Parameter] = field(default_factory=dict)
    ci_method: str = ""
    correlation: list[list[float]] | None = None
    optimizer: OptimizerRecord = field(default_factory=OptimizerRecord)
    convergence: dict[str, Any] | None = None
    metrics: dict[str, float] = field(default_factory=dict)
    statistics: dict[str, float] = field(default_factory=dict)
    statistics_note: str = ""
    operating_range: dict[str, list[float]] = field(default_factory=dict)
    provenance: dict[str, Any] = field(default_factory=dict)
    state: dict[str, Any] | None = None
    loss: dict[str, Any] = field(default_factory=dict)
    validation: dict[str, Any] | None = None
    selection: dict[str, Any] | None = None
    trust: dict[str, Any] | None = None
    prediction_interval: dict[str, Any] | None = None

    @classmethod
    def from_values(
        cls, model: str, values: Mapping[str, float], units: Mapping[str, str] | None = None, **kw
    ) -> FittedModel:
        """A model known by its parameters' values alone (a hand-made model, a backbone);
        ``kw`` are the other fields."""
        return cls(model=model, parameters=parameters_from_values(values, units), **kw)

    # -- views of the parameter records ----------------------------------------------------
    @property
    def params(self) -> Mapping[str, float]:
        """Every parameter's value by name, fixed ones included (read-only; lmfit's
        ``valuesdict``)."""
        return MappingProxyType({n: p.value for n, p in self.parameters.items()})

    @property
    def units(self) -> Mapping[str, str]:
        """Every parameter's unit by name (read-only)."""
        return MappingProxyType({n: p.unit for n, p in self.parameters.items()})

    @property
    def fixed(self) -> tuple[str, ...]:
        """The parameters held fixed, in the model's order."""
        return tuple(n for n, p in self.parameters.items() if p.fixed)

    @property
    def free(self) -> tuple[str, ...]:
        """The parameters the fit varied, in the model's order (the correlation's rows)."""
        return tuple(n for n, p in self.parameters.items() if not p.fixed)

    @property
    def at_bound(self) -> tuple[str, ...]:
        """The free parameters that ended on a bound of the search box."""
        return tuple(n for n, p in self.parameters.items() if p.at_bound)

    @property
    def converged(self) -> bool | None:
        """Whether the fit converged (the ``convergence`` block; None when not recorded)."""
        return None if self.convergence is None else bool(self.convergence.get("converged"))

    # -- prediction ----------------------------------------------------------------------
    @property
    def kind(self) -> str:
        """``"rbf"`` for a stateful model (the RBF network), else ``"analytic"``."""
        return "rbf" if get_predictor(self.model).stateful else "analytic"

    def friction_model(self):
        """The analytic :class:`~fricid.models.FrictionModel` behind this fit."""
        return get_model(self.model)

    def theta(self) -> np.ndarray:
        """The full parameter vector, in the model's order."""
        return self.friction_model().param_vector(self.params)

    def predict(self, X, *, warn: bool = True, return_std: bool = False):
        """Friction [N m] at inputs ``X`` (n, 3): velocity [rad/s], load [N m], temp [degC].

        Dispatched by model: the registered model's ``predict`` gets the stored state
        (stateful models: the RBF network) or the parameter vector (analytic models).

        Parameters
        ----------
        X : array_like, shape (n, 3)
            The inputs.
        warn : bool, default True
            Warn (:class:`~fricid.errors.ExtrapolationWarning`, one per quantity) when inputs
            lie outside the operating range (:meth:`range_check`): above the identified
            speeds, on a side a one-direction model was not identified on, or outside the
            load or temperature range. Speeds below the smallest identified one, and in a
            gap between measured speeds, are reported by :meth:`range_check` but not warned
            about here (every reversal passes through them).
        return_std : bool, default False
            Also return the predictive standard deviation [N m] of the friction (models with
            a posterior: ``"gp"``); a ``ConfigError`` for the others.
        """
        model = get_predictor(self.model)
        if return_std and self.model != "gp":
            raise ConfigError(f"model '{self.model}' has no predictive standard deviation")
        arg = self.state if model.stateful else self.theta()
        out = model.predict(arg, X, return_std=True) if return_std else model.predict(arg, X)
        if warn:
            self._warn_range(X)
        return out

    def predict_interval(self, X, level: float = 0.95, *, warn: bool = True) -> PredictionInterval:
        """Friction [N m] at ``X`` (n, 3) with its prediction interval at ``level``: where a
        new measured sample falls with probability ``level``, measurement noise included.

        Analytic models: the delta method from the parameters' covariance and the residual
        variance stored at the fit, its multiplier calibrated on the fit's leave-one-out
        residuals; ``gp``: its posterior with the fitted noise; ``rbf`` and
        ``hybrid``: the conformal half-widths stored with the network (levels 0.9 and 0.95).
        See :mod:`fricid.fitted._interval`. Warns as :meth:`predict` does; outside the
        operating range the interval is not backed by data.

        Raises
        ------
        ConfigError
            A level outside (0, 1), or a model file that stores no interval (at that level).
        """
        out = prediction_interval(self, X, level)
        if warn:
            self._warn_range(X)
        return out

    def _warn_range(self, X, stacklevel: int = 3) -> None:
        for bad in self.range_check(X):
            if bad.kind not in ("below", "gap"):
                warnings.warn(bad.message, ExtrapolationWarning, stacklevel=user_stacklevel())

    def predict_point(self, velocity, load=0.0, temperature=25.0) -> np.ndarray:
        """Friction [N m] at broadcastable velocity [rad/s], load [N m], temperature [degC];
        warns as :meth:`predict` does."""
        v, lo, t = np.broadcast_arrays(
            np.asarray(velocity, float), np.asarray(load, float), np.asarray(temperature, float)
        )
        X = np.column_stack([v.ravel(), lo.ravel(), t.ravel()])
        out = self.predict(X, warn=False).reshape(v.shape)
        self._warn_range(X)
        return out

    def inputs_used(self) -> tuple[str, ...]:
        """The inputs the model uses: the RBF network's (those its state names, and inputs it
        dropped for not varying), an analytic model's ``inputs``."""
        if self.kind != "rbf":
            return tuple(self.friction_model().inputs)
        state = self.state if isinstance(self.state, dict) else {}
        names: set[str] = set()
        for net in (state, state.get("pos"), state.get("neg")):
            if isinstance(net, dict):
                names.update(n for n in net.get("inputs") or () if n in INPUTS)
                names.update(n for n in net.get("dropped_inputs") or {} if n in INPUTS)
        return tuple(n for n in INPUTS if n in names) or INPUTS

    def range_check(self, X) -> list[RangeViolation]:
        """The inputs of ``X`` outside the operating range the model was identified on
        (issue 11, defect 8).

        Each input the model uses is compared with ``operating_range`` (inputs without a
        recorded range are not checked), allowing :data:`RANGE_TOLERANCE` of the span at the
        edges. Velocity: a model of combined samples (direction 0, odd in velocity) is
        compared by speed ``|v|`` (``"above"``, ``"below"``); a one-direction model by speed
        and side (``"side"``); a range spanning both directions by value (``"outside"``).
        Where the file records the measured speeds per direction (``provenance["speeds"]``,
        :func:`fricid.models._range.speed_coverage`), speeds below the slowest measured one
        of their direction are ``"below"`` for every model, and speeds in a gap between
        measured speeds are ``"gap"``. ``v = 0`` is never out of range (``sign(0) = 0``).

        Parameters
        ----------
        X : array_like, shape (n, 3)
            Velocity [rad/s], load [N m], temperature [degC].

        Returns
        -------
        list of RangeViolation
            One per quantity and kind found, empty when every input is inside.
        """
        prov = self.provenance or {}
        return range_violations(
            X, self.operating_range, self.inputs_used(), prov.get("directions"), prov.get("speeds")
        )

    def outside_range(self, X) -> np.ndarray:
        """Per row of ``X (n, 3)``: whether it lies outside the operating range
        (:meth:`range_check`: another side, above or below the measured speeds, other loads
        or temperatures; a gap between measured speeds is not outside)."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        rows = [v.rows for v in self.range_check(X) if v.kind != "gap" and v.rows is not None]
        return np.any([np.zeros(len(X), dtype=bool), *rows], axis=0)

    # -- text ----------------------------------------------------------------------------
    def report(self, min_correl: float = MIN_CORREL) -> str:
        """A plain-text fit report after lmfit's ``fit_report``, from what the file stores.

        Parameters
        ----------
        min_correl : float, default 0.1
            Correlations of at most this magnitude are left out.

        Returns
        -------
        str
            First, for a fit that did not converge, a line ``NOT CONVERGED: <reason>; <what
            to do>``. ``[[Model]]``; ``[[Fit Statistics]]`` (method, evaluations, status,
            convergence as certified, data points, variables, chi-square, reduced chi-square,
            AIC, BIC, R-squared, RMSE [N m]); ``[[Variables]]`` (value +/- standard error
            (relative), the
            95 % interval ``[low, high]`` and how it was found, start, and the flags "fixed",
            "at boundary", "at initial value", "not determined", and the reason a parameter
            has no interval or a side reaches a bound), or ``[[Network]]`` for the RBF
            network; ``[[Correlations]]`` above ``min_correl``, largest first. Files from
            before the intervals were stored print ``95 % CI +/- half-width`` as they did.
        """
        return fit_report(self, min_correl)

    # -- JSON ----------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """The model file's JSON document (schema version :data:`SCHEMA_VERSION`)."""
        d: dict[str, Any] = {f.name: getattr(self, f.name) for f in fields(self)}
        d["parameters"] = {n: p.to_dict() for n, p in self.parameters.items()}
        d["optimizer"] = self.optimizer.to_dict()
        history = self.optimizer.history
        d["optimizer"]["history"] = _downsample(np.asarray(history) if history else None)
        return _clean({"schema_version": SCHEMA_VERSION, "fricid_version": __version__, **d})

    @classmethod
    def from_dict(cls, d: dict[str, Any], source: str | None = None) -> FittedModel:
        """The model a parsed model file describes, checked as strictly as :meth:`load`.

        Parameters
        ----------
        d : dict
            The parsed JSON document.
        source : str, optional
            The file it came from, named in every error.

        Raises
        ------
        DataError
            The document is not a model file of a version this fricid reads, does not match
            the schema (``fricid/schemas/model.schema.json``: finite numbers of at most 1e300
            in magnitude, bounded sizes), names an unknown model or parameters, has a parameter
            outside its family's valid region (``fricid.models.Parameter.region``: ``w_s > 0``,
            ``tau_c >= 0``, ...), has a range or bound whose minimum exceeds its maximum, or
            gives a model that cannot be evaluated, or predicts a non-finite friction, on its
            operating range.

        Notes
        -----
        A file of schema version 1 (one object per field of the parameters, the optimiser's
        record in two places) is read through :func:`fricid.fitted._migrate.upgrade` and
        saves in the current layout.

        An RBF network from before ``state["symmetry"]`` was recorded is read with
        :func:`fricid.models.rbf.legacy_symmetry`: trained on combined samples (provenance
        directions ``[0]``, so on ``v > 0`` only) it is read as odd, ``F = sign(v) g(|v|)``,
        which repairs the wrong sign such files gave at ``v < 0``; any other stays "signed"
        (the network as trained).
        """
        if not isinstance(d, dict):
            raise DataError("a model file must hold a JSON object", file=source)
        check_document(d, source)
        version = d.get("schema_version")
        if not isinstance(version, int):
            raise DataError("not a fricid model file (no integer 'schema_version')", file=source)
        if version > SCHEMA_VERSION:
            raise DataError(
                f"model file schema version {version} is newer than this fricid "
                f"({__version__}) understands (version {SCHEMA_VERSION}); upgrade fricid",
                file=source,
            )
        _validate_schema(d, source)
        if version < SCHEMA_VERSION:
            d = upgrade(d, source)
        plain = {f.name for f in fields(cls)} - {"parameters", "optimizer"}
        kwargs = {k: d[k] for k in plain if k in d}
        if "statistics" in kwargs:
            kwargs["statistics"] = {k: _num(v) for k, v in kwargs["statistics"].items()}
        conv = kwargs.get("convergence")
        converged = None if not isinstance(conv, dict) else bool(conv.get("converged"))
        out = cls(
            parameters={
                n: Parameter.from_dict(n, r, converged) for n, r in d["parameters"].items()
            },
            optimizer=OptimizerRecord.from_dict(d.get("optimizer")),
            **kwargs,
        )
        try:
            stateful = get_predictor(out.model).stateful
        except ConfigError as exc:
            raise DataError(one_line(str(exc)), file=source) from None
        if stateful and isinstance(out.state, dict) and "symmetry" not in out.state:
            # a network written before the symmetry was recorded: one on combined samples
            # (v > 0) is read as odd, which repairs its sign at v < 0 (issue 11, defect 1)
            directions = (out.provenance or {}).get("directions")
            out.state = {**out.state, "symmetry": legacy_symmetry(directions)}
        if not stateful:
            try:
                theta = out.theta()
            except ConfigError as exc:  # unknown model, or parameter names that do not match
                raise DataError(one_line(str(exc)), file=source) from None
            _check_region(out.friction_model(), theta, "parameters", out.model, source)
        rows = out.correlation or []
        if any(len(row) != len(rows) for row in rows):
            raise DataError("field 'correlation': not a square matrix", file=source)
        spans = [(f"operating_range/{n}", pair) for n, pair in out.operating_range.items()]
        spans += [(f"parameters/{n}/bounds", p.bounds) for n, p in out.parameters.items()]
        for where, pair in spans:
            if pair is not None and pair[0] > pair[1]:
                raise DataError(
                    f"field '{where}': the minimum {pair[0]!r} exceeds the maximum {pair[1]!r}",
                    file=source,
                )
        out._check_predictions(source)
        return out

    def _check_predictions(self, source: str | None) -> None:
        """Evaluate the model on a grid over its operating range; a model that cannot be
        evaluated, or predicts a non-finite friction, there gives a :class:`DataError`.

        The grid takes each input's minimum, middle and maximum, and zero where the range
        spans it (sign(v) and the viscous terms change there); an input without a recorded
        range takes velocities +-0.01 and +-1 rad/s and zero, load 0 N m and 25 degC.
        """
        X = _probe_inputs(self.operating_range)
        model = get_predictor(self.model)
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")  # extrapolation and the like: not the question here
            try:
                y = np.asarray(model.predict(self.state if model.stateful else self.theta(), X))
            except FricidError as exc:
                column = getattr(exc, "column", None)
                where = f"field '{column.replace('.', '/')}': " if column else ""
                message = one_line(getattr(exc, "message", str(exc)))
                raise DataError(where + message, file=source) from None
            except (TypeError, ValueError, IndexError, KeyError, ArithmeticError) as exc:
                # the trust boundary: whatever the file holds, loading it ends in a DataError
                raise DataError(
                    f"the model cannot be evaluated: {one_line(str(exc))[:200]}", file=source
                ) from None
        bad = ~np.isfinite(y.astype(float, copy=False))
        if y.shape != (len(X),) or bad.any():
            at = X[int(np.argmax(bad))] if y.shape == (len(X),) else X[0]
            raise DataError(
                f"the model predicts a non-finite friction on its operating range (at velocity "
                f"{at[0]:g} rad/s, load {at[1]:g} N m, temperature {at[2]:g} degC)",
                file=source,
            )

    def save(self, path: str | PathLike[str]) -> Path:
        """Write the model as JSON, atomically."""
        from ..io._jsonfile import write_json

        return write_json(path, self.to_dict())

    @classmethod
    def load(cls, path: str | PathLike[str]) -> FittedModel:
        """Read a JSON model file strictly (see the module notes and :meth:`from_dict`).

        Raises
        ------
        DataError
            One line naming ``path`` as given: the file cannot be read, is over 64 MiB, not
            UTF-8, not JSON, nested over 64 deep, holds NaN, Infinity or a number beyond
            1e300, is of a newer version, does not match the schema, or gives a model that
            does not predict finite friction on its operating range.
        """
        d = read_json(path, what="model file")
        return cls.from_dict(d, source=str(path))
