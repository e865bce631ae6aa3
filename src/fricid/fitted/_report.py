"""The fit report of a :class:`~fricid.fitted.FittedModel`, after lmfit's ``fit_report``.

Printed from what the model file stores (:meth:`fricid.fitted.FittedModel.report` documents
the sections): the optimiser's record, the convergence verdict, the fit statistics, one line
per parameter record, and the correlations.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..models import get_predictor
from ._file import _convergence_line, _num
from ._parameter import Parameter

__all__ = ["MIN_CORREL", "fit_report"]

#: Correlations at or below this magnitude are left out of the fit report (lmfit's default).
MIN_CORREL = 0.1


def fit_report(fitted: Any, min_correl: float = MIN_CORREL) -> str:
    """The text of :meth:`fricid.fitted.FittedModel.report` for ``fitted`` (a
    :class:`~fricid.fitted.FittedModel`; not imported here, which imports this module)."""
    lines = []
    conv, opt = fitted.convergence, fitted.optimizer
    if conv is not None and not conv.get("converged"):
        lines.append(
            f"NOT CONVERGED: {conv.get('reason', '')}; "
            f"{conv.get('advice', '')}. No confidence intervals."
        )
    lines += ["[[Model]]", f"    {fitted.model}", "[[Fit Statistics]]"]
    lines.append(f"    # fitting method   = {opt.method} (seed {opt.seed})")
    lines.append(f"    # function evals   = {opt.nfev}")
    if opt.status is not None:
        lines.append(f"    # status           = {opt.status}: {opt.message}")
    if conv is not None:
        line = _convergence_line(conv, opt.nfev, opt.max_evals)
        lines.append(f"    # convergence      = {line}")
    st = fitted.statistics
    n = st.get("ndata", fitted.metrics.get("n"))
    if n is not None:
        lines.append(f"    # data points      = {int(n)}")
    if st.get("nvarys") is not None:
        lines.append(f"    # variables        = {int(st['nvarys'])}")
    elif st.get("nvarys_effective") is not None:
        lines.append(f"    # variables        = {st['nvarys_effective']:.4g} (effective)")
    if fitted.statistics_note:
        lines.append(f"    # statistics       = {fitted.statistics_note}")
    rows = (
        ("chi-square", st.get("chisqr", fitted.metrics.get("sse"))),
        ("reduced chi-square", st.get("redchi")),
        ("Akaike info crit", st.get("aic")),
        ("Bayesian info crit", st.get("bic")),
        ("R-squared", st.get("rsquared", fitted.metrics.get("fitness"))),
        ("RMSE [N m]", fitted.metrics.get("rmse")),
    )
    for k, v in rows:
        if v is None:
            continue
        if k == "reduced chi-square" and not math.isfinite(_num(v)):  # n = p: no dof
            lines.append(f"    {k:<18} = undefined (no more data points than variables)")
        else:
            lines.append(f"    {k:<18} = {_num(v):.8g}")
    model = get_predictor(fitted.model)
    if model.stateful:
        lines += ["[[Network]]", f"    {model.describe(fitted.state)}"]
        return "\n".join(lines)
    lines.append("[[Variables]]")
    width = max((len(name) for name in fitted.parameters), default=0) + 1
    for name, p in fitted.parameters.items():
        unit = "" if p.unit == "1" else p.unit  # dimensionless: "4 1 +/-" read as one number
        lines.append(f"    {name + ':':<{width}} {p.value: .8g} {unit}")
        lines[-1] = lines[-1].rstrip() + _variable_note(p, fitted.ci_method)
    if any(name.endswith(("_pos", "_neg")) for name in fitted.parameters):
        lines.append(f"    {DIRECTIONS}")
    lines += _shared_lines(fitted.provenance.get("shared_error"))
    lines += _correlation_lines(fitted, min_correl)
    return "\n".join(lines)


#: The legend of a per-direction model's parameters (a new user found it in the docs only).
DIRECTIONS = "(_pos: moving forwards, v >= 0; _neg: backwards, v < 0, given as magnitudes)"

#: An interval side longer than this many times 1.96 standard errors is said to be so (a
#: profile interval at a bound: a new user read "0.0215 +/- 0.00357 (95 % CI [0, 0.0537])"
#: as 17 % precision).
WIDER = 2.0


def _variable_note(p: Parameter, ci_method: str) -> str:
    """The fit report's text after a parameter's value: standard error, interval (found by
    ``ci_method``), start and flags."""
    if p.fixed:
        return " (fixed)"
    note = ""
    if np.isfinite(p.stderr):
        # relative only where it means something: a value near zero (its error as large as
        # itself) prints its absolute error alone, not "4.3e-24 +/- 8.4e25 %"
        rel = f" ({abs(p.stderr / p.value):.2%})" if abs(p.stderr) < abs(p.value) else ""
        note += f" +/- {p.stderr:.3g}{rel}"
        if p.has_interval:
            low, high = p.ci95
            note += f" (95 % CI [{low:.4g}, {high:.4g}], {ci_method or 'jacobian'})"
            wide = max(high - p.value, p.value - low) / (1.96 * p.stderr) if p.stderr > 0 else 0
            if wide > WIDER and not (p.not_determined or p.note):  # a note says why
                note += (
                    f" [the interval is {wide:.2g}x +/- 1.96 standard errors: read it, not the +/-]"
                )
        elif np.isfinite(p.ci95_halfwidth):
            note += f" (95 % CI +/- {p.ci95_halfwidth:.3g})"
    if p.init is not None:
        note += f" (init = {p.init:.8g})"
    flags = []
    if p.at_bound:
        flags.append("at boundary")
    if p.at_initial_value:
        flags.append("at initial value")
    if p.not_determined and not p.note.startswith("not identified"):
        flags.append("not determined")  # a "not identified" note says it itself
    ends = [side for side, is_open in (("lower", p.low_open), ("upper", p.high_open)) if is_open]
    if ends and not (p.note or p.at_bound):  # a note says why (both open: not identified)
        flags.append(
            f"not bounded by the data: the interval reaches the search range's {ends[0]} end"
        )
    if p.note:
        flags.append(p.note.removeprefix("not determined: "))
    return note + "".join(f" [{f}]" for f in flags)


def _shared_lines(shared: Any) -> list[str]:
    """What the standard errors and intervals include beyond the residuals' scatter: an
    error every sample shares (``provenance["shared_error"]``), with each share of variance."""
    if not isinstance(shared, dict):
        return []
    share = shared.get("variance_share") or {}
    parts = ", ".join(
        f"{name} {100 * float(s):.0f} %" for name, s in share.items() if isinstance(s, int | float)
    )
    return [
        f"    # the errors above include one every sample shares: {shared.get('source', '')}"
        + (f" (share of variance: {parts})" if parts else "")
    ]


def _correlation_lines(fitted: Any, min_correl: float) -> list[str]:
    """``C(a, b) = r`` for the pairs above ``min_correl``, largest magnitude first."""
    if not fitted.correlation:
        return []
    names = fitted.free
    corr = np.asarray(fitted.correlation, dtype=float)
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
