"""One record per parameter, and the optimiser's record, of a fitted model.

:class:`Parameter` is one parameter as lmfit's ``Parameter`` holds it: its value and unit,
whether it was held fixed, its start and search bounds, its standard error and 95 % interval
with each end marked open where it reaches the search bound, why it has no interval, and the
flags the fit report prints (at a bound, not determined, at its initial value).
:class:`OptimizerRecord` is how the optimum was found: the method, its seed, why it stopped
(status and message), the evaluations spent and the budget, and the convergence history. Both
are immutable; a writer that learns more builds a new record (:func:`dataclasses.replace`).

In the model file (schema version 2) the parameters are one object per name under
``"parameters"`` (:meth:`Parameter.to_dict`), the optimiser's record is ``"optimizer"``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

__all__ = ["OptimizerRecord", "Parameter", "is_not_determined", "parameters_from_values"]

_NAN = float("nan")


def _float(value: Any) -> float:
    """A float, NaN for None (the file's null)."""
    return _NAN if value is None else float(value)


def is_not_determined(note: str, stderr: float, converged: bool | None) -> bool:
    """Whether the data do not determine a free parameter.

    Its note says so (``"not determined: ..."``, ``"not identified: ..."``), or, with no note,
    it has no finite standard error from a fit not known to have failed to converge (a fit that
    did not converge has no standard errors at all; that is said by the convergence block).
    """
    if note.startswith(("not determined", "not identified")):
        return True
    return not note and not math.isfinite(stderr) and converged is not False


@dataclass(frozen=True)
class Parameter:
    """One parameter of a fitted model (after lmfit's ``Parameter``).

    Attributes
    ----------
    name : str
        The parameter's name (the paper's).
    value : float
        Its value, SI units.
    unit : str
        Its unit (``"N m"``, ``"rad/s"``, ...); ``""`` when not recorded.
    fixed : bool
        Held at ``value`` during the fit.
    init : float or None
        Where the optimiser started (free parameters of fits that record it).
    bounds : (float, float) or None
        The search box ``(low, high)`` of a free parameter.
    stderr : float
        Standard error (NaN where there is none: fixed, not converged, not determined).
    ci95 : (float, float)
        The 95 % interval's ends, inside the search box (``FittedModel.ci_method`` says how it
        was found); NaNs where there is none.
    ci95_halfwidth : float
        Half-width of the linearised 95 % interval (``t stderr``; for the trajectory's
        cluster-robust interval, half its length); NaN where there is none. Files from
        before the ends were recorded have only this.
    low_open, high_open : bool
        That end of the interval reaches the search bound: the data do not bound the
        parameter on that side.
    note : str
        Why the parameter has no interval, or why an end is open; ``""`` otherwise.
    at_bound : bool
        The fit ended on a bound of the search box.
    not_determined : bool
        The data do not determine it (:func:`is_not_determined`).
    """

    name: str
    value: float
    unit: str = ""
    fixed: bool = False
    init: float | None = None
    bounds: tuple[float, float] | None = None
    stderr: float = _NAN
    ci95: tuple[float, float] = (_NAN, _NAN)
    ci95_halfwidth: float = _NAN
    low_open: bool = False
    high_open: bool = False
    note: str = ""
    at_bound: bool = False
    not_determined: bool = False

    @property
    def at_initial_value(self) -> bool:
        """The fit left the parameter where it started (a sign it did not move it)."""
        return self.init is not None and self.value == self.init

    @property
    def has_interval(self) -> bool:
        """Both ends of the 95 % interval are recorded."""
        return math.isfinite(self.ci95[0]) and math.isfinite(self.ci95[1])

    @property
    def one_bound(self) -> str:
        """``"at most 1.31"`` (or ``"at least ..."``): the one bound an interval open at one
        end of the search range sets; ``""`` for any other interval."""
        if self.low_open == self.high_open or not self.has_interval:
            return ""
        low, high = (float(x) for x in self.ci95)
        return f"at most {high:.4g}" if self.low_open else f"at least {low:.4g}"

    def to_dict(self) -> dict[str, Any]:
        """The record as the model file holds it (without the name, its key); NaN stays NaN
        here and becomes null when the file is written."""
        return {
            "value": self.value,
            "unit": self.unit,
            "fixed": self.fixed,
            "init": self.init,
            "bounds": None if self.bounds is None else list(self.bounds),
            "stderr": self.stderr,
            "ci95": list(self.ci95),
            "ci95_halfwidth": self.ci95_halfwidth,
            "low_open": self.low_open,
            "high_open": self.high_open,
            "note": self.note,
            "at_bound": self.at_bound,
            "not_determined": self.not_determined,
        }

    @classmethod
    def from_dict(cls, name: str, d: Mapping[str, Any], converged: bool | None = None) -> Parameter:
        """The record of a model file's ``parameters[name]`` (checked by the schema).

        Missing keys take the defaults, but for ``not_determined``: without it, a free
        parameter is judged by :func:`is_not_determined` with ``converged`` (the fit's
        convergence, None when not recorded), as files without the flag were read.
        """
        bounds = d.get("bounds")
        ci95 = d.get("ci95") or (None, None)
        init = d.get("init")
        fixed, note, stderr = bool(d.get("fixed", False)), str(d.get("note", "")), d.get("stderr")
        flag = d.get("not_determined")
        if flag is None:
            flag = not fixed and is_not_determined(note, _float(stderr), converged)
        return cls(
            name=name,
            value=float(d["value"]),
            unit=str(d.get("unit", "")),
            fixed=fixed,
            init=None if init is None else float(init),
            bounds=None if bounds is None else (float(bounds[0]), float(bounds[1])),
            stderr=_float(stderr),
            ci95=(_float(ci95[0]), _float(ci95[1])),
            ci95_halfwidth=_float(d.get("ci95_halfwidth")),
            low_open=bool(d.get("low_open", False)),
            high_open=bool(d.get("high_open", False)),
            note=note,
            at_bound=bool(d.get("at_bound", False)),
            not_determined=bool(flag),
        )


def parameters_from_values(
    values: Mapping[str, float], units: Mapping[str, str] | None = None
) -> dict[str, Parameter]:
    """Records of parameters known by value alone (a hand-made model, a backbone), in the
    order of ``values``; ``units`` by name where known."""
    units = units or {}
    return {n: Parameter(n, float(v), unit=str(units.get(n, ""))) for n, v in values.items()}


@dataclass(frozen=True)
class OptimizerRecord:
    """How the optimum was found: stored once per model (schema version 2: ``"optimizer"``).

    Attributes
    ----------
    method : str
        The method (an optimiser of :mod:`fricid.optim`, ``varpro``, a learned model's
        trainer); ``""`` when not recorded.
    seed : int or None
        Its random seed.
    status : int or None
        Why it stopped (:attr:`fricid.optim.OptimizeResult.status`: 0 converged, 1 budget
        spent, 2 stopped by the callback, 4 iteration limit); None when not recorded.
    message : str
        The optimiser's message for ``status``.
    nfev : int
        Model evaluations spent (one candidate parameter vector is one evaluation).
    max_evals : int or None
        The budget in evaluations (0: none applies, as for a closed-form solution); None
        when not recorded.
    history : list of [evaluations, best SSE] or None
        The convergence history, downsampled to at most 2000 points when written.
    """

    method: str = ""
    seed: int | None = None
    status: int | None = None
    message: str = ""
    nfev: int = 0
    max_evals: int | None = None
    history: list[list[float]] | None = None

    def to_dict(self) -> dict[str, Any]:
        """The record as the model file holds it."""
        return {
            "method": self.method,
            "seed": self.seed,
            "status": self.status,
            "message": self.message,
            "nfev": self.nfev,
            "max_evals": self.max_evals,
            "history": self.history,
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any] | None) -> OptimizerRecord:
        """The record of a model file's ``optimizer`` (checked by the schema); missing keys
        take the defaults."""
        d = d or {}
        status, max_evals = d.get("status"), d.get("max_evals")
        return cls(
            method=str(d.get("method", "")),
            seed=d.get("seed"),
            status=None if status is None else int(status),
            message=str(d.get("message", "")),
            nfev=int(d.get("nfev", 0)),
            max_evals=None if max_evals is None else int(max_evals),
            history=d.get("history"),
        )
