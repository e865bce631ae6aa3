"""``FittedModel``: an identified friction model with its metrics, uncertainty and provenance.

It is what ``identify.fit`` returns and what the JSON model file holds; reports, exports and
``fricid predict`` start from it. The JSON is plain (numbers, strings, lists), versioned by
``schema_version``, with SI units recorded per parameter. Prediction is dispatched by model
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

import json
import warnings
from dataclasses import asdict, dataclass, field
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__
from ..errors import ConfigError, DataError, ExtrapolationWarning, FricidError
from ..io._jsonfile import check_document, one_line, read_json
from ..models import INPUTS, get_model, get_predictor
from ..models._range import RANGE_TOLERANCE, RangeViolation, range_violations
from ..models.rbf import legacy_symmetry
from ._file import (
    SCHEMA_VERSION,
    _clean,
    _convergence_line,
    _downsample,
    _num,
    _probe_inputs,
    _validate_schema,
)

__all__ = ["MIN_CORREL", "RANGE_TOLERANCE", "SCHEMA_VERSION", "FittedModel", "RangeViolation"]

#: Correlations at or below this magnitude are left out of the fit report (lmfit's default).
MIN_CORREL = 0.1


def _check_region(model, theta, field_name: str, name: str, source: str | None) -> None:
    """A :class:`DataError` naming the file and the first parameter of ``theta`` outside the
    valid region its family declares (``fricid.models.Parameter.region``)."""
    bad = model.region_violation(theta)
    if bad is not None:
        param, value = bad
        raise DataError(
            f"field '{field_name}/{param.name}': {value!r} lies outside model '{name}''s valid "
            f"region ({param.rule}, the {param.description})",
            file=source,
        )


@dataclass
class FittedModel:
    """An identified model.

    Attributes
    ----------
    model : registry name of the model (``fricid.models.MODELS``, ``*_asym``, or ``"rbf"``).
    params : every parameter's value, fixed ones included (SI units, see ``units``).
    units : unit of each parameter.
    fixed : names of the parameters held fixed during the fit.
    stderr : standard error of each free parameter from the Jacobian at the optimum
        (``cov = s^2 (J^T J)^+``, an SVD pseudo-inverse as scipy's ``curve_fit``,
        ``s^2 = SSE / (n - p)``); NaN where not determined, and for every parameter of a fit
        that did not converge or whose optimum is degenerate (``uncertainty_note`` says why).
    ci95 : half-width of the linearised 95 % interval ``t(0.975, n - p) * stderr`` (NaN where
        ``stderr`` is); the interval to use is ``ci95_low`` .. ``ci95_high``.
    ci95_low, ci95_high : ends of the 95 % interval, inside the search box (profile
        likelihood, or the linearised interval cut at the box: ``ci_method``); NaN where there
        is none. Empty in files written before they were.
    ci_open : per free parameter, ``[lower, upper]``: that side of the interval reaches the
        search bound (the data do not bound the parameter there).
    ci_method : ``"profile"``, ``"jacobian"`` or ``""`` (no intervals).
    uncertainty_note : why a parameter has no interval, or why a side is open.
    convergence : the convergence block (``fricid.identify.static.convergence.certify``):
        ``converged``, ``status``, ``message``, ``nfev``, ``max_evals``, ``polish_sse_ratio``,
        ``polish_nfev``, ``certified_by`` and, when not converged, ``reason`` and ``advice``;
        None when not recorded.
    at_bound : free parameters that ended on a bound of the search box (their
        uncertainty is not meaningful).
    correlation : correlation matrix of the free parameters (list of lists), or None.
    metrics : fit metrics on the identification data (``fricid.metrics.metrics``).
    method, seed, nfev : how it was found; ``history`` is (nfev, best SSE) pairs.
    status, message : why the optimiser stopped (``fricid.optim.OptimizeResult.status``: 0
        converged, 1 budget spent, 2 stopped by the callback, 4 iteration limit); None and ""
        when not recorded (files from before they were).
    init : starting value of each free parameter.
    statistics : fit statistics after lmfit: ``ndata``, ``nvarys``, ``nfree``, ``chisqr``
        (the SSE), ``redchi``, ``aic``, ``bic``, ``rsquared``
        (:func:`fricid.metrics.fit_statistics`); for the learned models ``nvarys_effective``
        and ``nfree_effective`` (the effective degrees of freedom, the trace of the hat
        matrix) in place of ``nvarys`` and ``nfree``, or neither and no AIC, BIC or reduced
        chi-square where they are undefined (:mod:`fricid.identify.learned._trust`).
    statistics_note : how the statistics count the model's degrees of freedom, or why some
        are not given ("" for an analytic fit: its free parameters).
    bounds : the search box of each free parameter.
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
    trust : the trust verdict and where each of its numbers came from
        (:class:`fricid.identify.trust.Trust`, ``to_dict()``), with what it was computed on
        (samples and model hashes, options); None when not assessed. ``fricid fit`` and the
        fleet store it; ``fricid report`` reuses it only for the same samples and options.
    """

    model: str
    params: dict[str, float]
    units: dict[str, str] = field(default_factory=dict)
    fixed: list[str] = field(default_factory=list)
    stderr: dict[str, float] = field(default_factory=dict)
    ci95: dict[str, float] = field(default_factory=dict)
    at_bound: list[str] = field(default_factory=list)
    correlation: list[list[float]] | None = None
    metrics: dict[str, float] = field(default_factory=dict)
    method: str = ""
    seed: int | None = None
    nfev: int = 0
    history: list[list[float]] | None = None
    bounds: dict[str, list[float]] = field(default_factory=dict)
    operating_range: dict[str, list[float]] = field(default_factory=dict)
    provenance: dict[str, Any] = field(default_factory=dict)
    state: dict[str, Any] | None = None
    status: int | None = None
    message: str = ""
    init: dict[str, float] = field(default_factory=dict)
    statistics: dict[str, float] = field(default_factory=dict)
    ci95_low: dict[str, float] = field(default_factory=dict)
    ci95_high: dict[str, float] = field(default_factory=dict)
    ci_open: dict[str, list[bool]] = field(default_factory=dict)
    ci_method: str = ""
    uncertainty_note: dict[str, str] = field(default_factory=dict)
    convergence: dict[str, Any] | None = None
    statistics_note: str = ""

    @property
    def converged(self) -> bool | None:
        """Whether the fit converged (the ``convergence`` block; None when not recorded)."""
        return None if self.convergence is None else bool(self.convergence.get("converged"))

    loss: dict[str, Any] = field(default_factory=dict)
    validation: dict[str, Any] | None = None
    selection: dict[str, Any] | None = None
    trust: dict[str, Any] | None = None

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
            load or temperature range. Speeds below the smallest identified one are
            reported by :meth:`range_check` but not warned about here (every reversal passes
            through them).
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

    def _warn_range(self, X, stacklevel: int = 3) -> None:
        for bad in self.range_check(X):
            if bad.kind != "below":
                warnings.warn(bad.message, ExtrapolationWarning, stacklevel=stacklevel)

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
        ``v = 0`` is never out of range (``sign(0) = 0``).

        Parameters
        ----------
        X : array_like, shape (n, 3)
            Velocity [rad/s], load [N m], temperature [degC].

        Returns
        -------
        list of RangeViolation
            One per quantity and kind found, empty when every input is inside.
        """
        dirs = (self.provenance or {}).get("directions") if self.provenance else None
        return range_violations(X, self.operating_range, self.inputs_used(), dirs)

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
            AIC, BIC, R-squared); ``[[Variables]]`` (value +/- standard error (relative), the
            95 % interval ``[low, high]`` and how it was found, start, and the flags "fixed",
            "at boundary", "at initial value", "not determined", and the reason a parameter
            has no interval or a side reaches a bound), or ``[[Network]]`` for the RBF
            network; ``[[Correlations]]`` above ``min_correl``, largest first. Files from
            before the intervals were stored print ``95 % CI +/- half-width`` as they did.
        """
        lines = []
        conv = self.convergence
        if conv is not None and not conv.get("converged"):
            lines.append(
                f"NOT CONVERGED: {conv.get('reason', conv.get('message', ''))}; "
                f"{conv.get('advice', '')}. No confidence intervals."
            )
        lines += ["[[Model]]", f"    {self.model}", "[[Fit Statistics]]"]
        lines.append(f"    # fitting method   = {self.method} (seed {self.seed})")
        lines.append(f"    # function evals   = {self.nfev}")
        if self.status is not None:
            lines.append(f"    # status           = {self.status}: {self.message}")
        if conv is not None:
            lines.append(f"    # convergence      = {_convergence_line(conv)}")
        st = self.statistics
        n = st.get("ndata", self.metrics.get("n"))
        if n is not None:
            lines.append(f"    # data points      = {int(n)}")
        if st.get("nvarys") is not None:
            lines.append(f"    # variables        = {int(st['nvarys'])}")
        elif st.get("nvarys_effective") is not None:
            lines.append(f"    # variables        = {st['nvarys_effective']:.4g} (effective)")
        if self.statistics_note:
            lines.append(f"    # statistics       = {self.statistics_note}")
        rows = (
            ("chi-square", st.get("chisqr", self.metrics.get("sse"))),
            ("reduced chi-square", st.get("redchi")),
            ("Akaike info crit", st.get("aic")),
            ("Bayesian info crit", st.get("bic")),
            ("R-squared", st.get("rsquared", self.metrics.get("fitness"))),
        )
        lines += [f"    {k:<18} = {_num(v):.8g}" for k, v in rows if v is not None]
        model = get_predictor(self.model)
        if model.stateful:
            lines += ["[[Network]]", f"    {model.describe(self.state)}"]
            return "\n".join(lines)
        lines.append("[[Variables]]")
        width = max((len(name) for name in self.params), default=0) + 1
        for name, value in self.params.items():
            lines.append(f"    {name + ':':<{width}} {value: .8g} {self.units.get(name, '')}")
            lines[-1] = lines[-1].rstrip() + self._variable_note(name, value)
        lines += self._correlation_lines(min_correl)
        return "\n".join(lines)

    def _variable_note(self, name: str, value: float) -> str:
        if name in self.fixed:
            return " (fixed)"
        se = _num(self.stderr.get(name))
        note = ""
        if np.isfinite(se):
            rel = f" ({abs(se / value):.2%})" if value != 0 else ""
            note += f" +/- {se:.3g}{rel}"
            low, high = _num(self.ci95_low.get(name)), _num(self.ci95_high.get(name))
            if np.isfinite(low) and np.isfinite(high):
                note += f" (95 % CI [{low:.4g}, {high:.4g}], {self.ci_method or 'jacobian'})"
            elif np.isfinite(_num(self.ci95.get(name))):
                note += f" (95 % CI +/- {_num(self.ci95.get(name)):.3g})"
        if name in self.init:
            note += f" (init = {self.init[name]:.8g})"
        why = self.uncertainty_note.get(name, "")
        flags = []
        if name in self.at_bound:
            flags.append("at boundary")
        if name in self.init and value == self.init[name]:
            flags.append("at initial value")
        if not np.isfinite(se) and (not why or why.startswith("not determined")):
            flags.append("not determined")
        if why:
            flags.append(why.removeprefix("not determined: "))
        return note + "".join(f" [{f}]" for f in flags)

    def _correlation_lines(self, min_correl: float) -> list[str]:
        """``C(a, b) = r`` for the pairs above ``min_correl``, largest magnitude first."""
        if not self.correlation:
            return []
        names = list(self.stderr)
        corr = np.asarray(self.correlation, dtype=float)
        if corr.shape != (len(names), len(names)):
            return []
        pairs = [
            (float(corr[i, j]), names[i], names[j])
            for i in range(len(names))
            for j in range(i + 1, len(names))
            if np.isfinite(corr[i, j]) and abs(corr[i, j]) > min_correl
        ]
        if not pairs:
            return []
        pairs.sort(key=lambda p: -abs(p[0]))
        head = f"[[Correlations]] (unreported correlations are <= {min_correl:.3f})"
        return [head] + [f"    C({a}, {b}) = {r:+.4f}" for r, a, b in pairs]

    # -- JSON ----------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["history"] = _downsample(np.asarray(self.history) if self.history else None)
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
        known = set(cls.__dataclass_fields__)
        kwargs = {k: v for k, v in d.items() if k in known}
        if "model" not in kwargs or "params" not in kwargs:
            raise DataError("model file lacks 'model' or 'params'", file=source)
        for key in ("params", "stderr", "ci95", "ci95_low", "ci95_high", "init", "statistics"):
            if key in kwargs:
                kwargs[key] = {k: _num(v) for k, v in kwargs[key].items()}
        out = cls(**kwargs)
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
            _check_region(out.friction_model(), theta, "params", out.model, source)
        rows = out.correlation or []
        if any(len(row) != len(rows) for row in rows):
            raise DataError("field 'correlation': not a square matrix", file=source)
        for key in ("operating_range", "bounds"):
            for name, (low, high) in getattr(out, key).items():
                if low > high:
                    raise DataError(
                        f"field '{key}/{name}': the minimum {low!r} exceeds the maximum {high!r}",
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
        from ..io.atomic import atomic_write

        path = Path(path)
        with atomic_write(path, "w") as fh:
            json.dump(self.to_dict(), fh, indent=2)
            fh.write("\n")
        return path

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
