"""``FittedModel``: an identified friction model with its metrics, uncertainty and provenance.

It is what ``identify.fit`` returns and what the JSON model file holds; reports, exports and
``fricid predict`` start from it. The JSON is plain (numbers, strings, lists), versioned by
``schema_version``, with SI units recorded per parameter.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from functools import lru_cache
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np

from . import __version__
from .errors import ConfigError, DataError
from .models import get_model

__all__ = ["SCHEMA_VERSION", "FittedModel"]

#: Version of the JSON model file this fricid writes and reads.
SCHEMA_VERSION = 1

#: Longest convergence history kept in a model file (downsampled evenly, last point kept).
MAX_HISTORY = 2000


def _downsample(history: np.ndarray | None) -> list[list[float]] | None:
    if history is None or len(history) == 0:
        return None
    h = np.asarray(history, dtype=float)
    if len(h) > MAX_HISTORY:
        idx = np.unique(np.linspace(0, len(h) - 1, MAX_HISTORY).round().astype(int))
        h = h[idx]
    return h.tolist()


def _clean(value: Any) -> Any:
    """JSON-ready: numpy to Python, non-finite floats to None."""
    if isinstance(value, dict):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_clean(v) for v in value]
    if isinstance(value, np.ndarray):
        return _clean(value.tolist())
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, float | np.floating):
        f = float(value)
        return f if np.isfinite(f) else None
    return value


def _num(value: Any) -> float:
    return float("nan") if value is None else float(value)


@lru_cache(maxsize=1)
def _schema_validator():
    """The validator of the model file's JSON Schema (``fricid/schemas/model.schema.json``)."""
    from importlib.resources import files

    from jsonschema import Draft202012Validator

    text = files("fricid").joinpath("schemas", "model.schema.json").read_text(encoding="utf-8")
    return Draft202012Validator(json.loads(text))


def _validate_schema(d: dict[str, Any], source: str | None) -> None:
    """Raise a :class:`DataError` naming the file and the first failing field."""
    from jsonschema.exceptions import best_match

    error = best_match(_schema_validator().iter_errors(d))
    if error is None:
        return
    where = "/".join(str(p) for p in error.absolute_path) or "(top level)"
    message = error.message if len(error.message) <= 200 else error.message[:197] + "..."
    raise DataError(
        f"field '{where}' does not match the model file schema (version {SCHEMA_VERSION}): "
        f"{message}",
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
        (``cov = s^2 (J^T J)^-1``, ``s^2 = SSE / (n - p)``); NaN where not available.
    ci95 : half-width of the 95 % confidence interval (Student t, n - p degrees of freedom).
    at_bound : free parameters that ended on a bound of the search box (their
        uncertainty is not meaningful).
    correlation : correlation matrix of the free parameters (list of lists), or None.
    metrics : fit metrics on the identification data (``fricid.metrics.metrics``).
    method, seed, nfev : how it was found; ``history`` is (nfev, best SSE) pairs.
    bounds : the search box of each free parameter.
    operating_range : min and max of velocity, load and temperature in the data.
    provenance : data source, sample count, fricid version, creation time.
    state : model-specific arrays for non-analytic models (the RBF network).
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

    # -- prediction ----------------------------------------------------------------------
    @property
    def kind(self) -> str:
        return "rbf" if self.model == "rbf" else "analytic"

    def friction_model(self):
        """The analytic :class:`~fricid.models.FrictionModel` behind this fit."""
        return get_model(self.model)

    def theta(self) -> np.ndarray:
        """The full parameter vector, in the model's order."""
        return self.friction_model().param_vector(self.params)

    def predict(self, X) -> np.ndarray:
        """Friction [N m] at inputs ``X`` (n, 3): velocity [rad/s], load [N m], temp [degC]."""
        if self.kind == "rbf":
            from .models.rbf import predict_state

            return predict_state(self.state, X)
        return self.friction_model().predict(self.theta(), X)

    def predict_point(self, velocity, load=0.0, temperature=25.0) -> np.ndarray:
        """Friction [N m] at broadcastable velocity [rad/s], load [N m], temperature [degC]."""
        v, lo, t = np.broadcast_arrays(
            np.asarray(velocity, float), np.asarray(load, float), np.asarray(temperature, float)
        )
        X = np.column_stack([v.ravel(), lo.ravel(), t.ravel()])
        return self.predict(X).reshape(v.shape)

    # -- text ----------------------------------------------------------------------------
    def report(self) -> str:
        """A plain-text fit report (after lmfit's ``fit_report``)."""
        lines = [
            f"[[Model]] {self.model}   [[Method]] {self.method} (seed {self.seed}, "
            f"{self.nfev} evaluations)"
        ]
        m = self.metrics
        if m:
            lines.append(
                "[[Fit statistics]] "
                + ", ".join(
                    f"{k} = {m[k]:.6g}"
                    for k in ("n", "fitness", "sse", "rmse", "rmspe", "mae", "max_abs_error")
                    if k in m
                )
            )
        if self.kind == "rbf" and self.state:
            st = self.state
            lines.append(
                f"[[Network]] {len(st.get('centers', []))} Gaussian units (eq. 14), linear output "
                f"(eq. 15){' with bias' if st.get('fit_bias') else ''}; inputs "
                f"{', '.join(st.get('inputs', []))}; trainer {st.get('trainer')}"
                + (f", encoding {st['encoding']}" if st.get("encoding") else "")
                + (f", {st['n_epochs']} epochs" if st.get("n_epochs") else "")
            )
            return "\n".join(lines)
        lines.append("[[Parameters]]")
        for name, value in self.params.items():
            unit = self.units.get(name, "")
            if name in self.fixed:
                note = "(fixed)"
            else:
                se = self.stderr.get(name, float("nan"))
                ci = self.ci95.get(name, float("nan"))
                note = f"+/- {se:.3g} (95 % CI +/- {ci:.3g})" if np.isfinite(se) else ""
                if name in self.at_bound:
                    note += " at a bound"
            lines.append(f"    {name:>10} = {value: .6g} {unit:<12} {note}")
        return "\n".join(lines)

    # -- JSON ----------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["history"] = _downsample(np.asarray(self.history) if self.history else None)
        return _clean({"schema_version": SCHEMA_VERSION, "fricid_version": __version__, **d})

    @classmethod
    def from_dict(cls, d: dict[str, Any], source: str | None = None) -> FittedModel:
        if not isinstance(d, dict):
            raise DataError("a model file must hold a JSON object", file=source)
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
        for key in ("params", "stderr", "ci95"):
            if key in kwargs:
                kwargs[key] = {k: _num(v) for k, v in kwargs[key].items()}
        out = cls(**kwargs)
        if out.kind == "analytic":
            try:
                out.theta()
            except ConfigError as exc:  # unknown model, or parameter names that do not match
                raise DataError(str(exc), file=source) from None
        return out

    def save(self, path: str | PathLike[str]) -> Path:
        """Write the model as JSON, atomically."""
        from .io.atomic import atomic_write

        path = Path(path)
        with atomic_write(path, "w") as fh:
            json.dump(self.to_dict(), fh, indent=2)
            fh.write("\n")
        return path

    @classmethod
    def load(cls, path: str | PathLike[str]) -> FittedModel:
        """Read a JSON model file; a bad or newer file gives a :class:`DataError`."""
        path = Path(path)
        try:
            text = path.read_text(encoding="utf-8")
        except OSError as exc:
            raise DataError(f"cannot read the model file: {exc.strerror}", file=path) from None
        try:
            d = json.loads(text)
        except json.JSONDecodeError as exc:
            raise DataError(f"not valid JSON: {exc.msg}", file=path, row=exc.lineno) from None
        return cls.from_dict(d, source=str(path))
