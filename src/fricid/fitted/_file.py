"""The model file's plumbing: JSON-ready values, the JSON Schema check, probe inputs.

Helpers of :mod:`fricid.fitted` (kept apart so that the model type stays readable): values
made JSON-ready, the schema validator whose first error becomes one :class:`DataError` line
naming the file, the fit report's convergence line, and the grid on which a loaded model is
evaluated to prove it predicts finite friction on its operating range.
"""

from __future__ import annotations

import itertools
import json
from functools import lru_cache
from typing import Any

import numpy as np

from ..errors import DataError
from ..io._jsonfile import one_line
from ..models import INPUTS

#: Version of the JSON model file this fricid writes (it reads this one and version 1).
SCHEMA_VERSION = 2

#: Velocities probed where a model file records no velocity range [rad/s].
_PROBE_VELOCITY = (-1.0, -0.01, 0.0, 0.01, 1.0)
#: Load [N m] and temperature [degC] probed where a model file records no range.
_PROBE_DEFAULT = {"load": (0.0,), "temperature": (25.0,)}

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


#: What ``convergence["certified_by"]`` means, as the fit report and the report's trust
#: section say it.
CERTIFIED_BY = {
    "optimizer": "optimiser's own test",
    "polish": "local polish",
    "closed_form": "exact by construction: least squares in closed form",
    "target": "the trainer met its target training error",
}


def _convergence_line(
    conv: dict[str, Any], nfev: int | None = None, max_evals: int | None = None
) -> str:
    """The fit report's convergence line, from the model file's convergence block and, for a
    fit that did not converge, the optimiser's evaluations and budget."""
    ratio = _num(conv.get("polish_sse_ratio"))
    polish = f"local polish SSE ratio {ratio:.6g}" if np.isfinite(ratio) else "no polish"
    if conv.get("converged"):
        by = CERTIFIED_BY.get(str(conv.get("certified_by")), "recorded")
        if conv.get("certified_by") in ("closed_form", "target"):
            base = conv.get("backbone")
            tail = f"; backbone {_convergence_line(base)}" if isinstance(base, dict) else ""
            return f"converged ({by}{tail})"
        return f"converged (certified by the {by}; {polish})"
    spent = (
        f"{nfev} evaluations, budget {max_evals}"  # carried on past it from a polish
        if nfev is not None and max_evals is not None and nfev > max_evals
        else f"{nfev} of {max_evals} evaluations"
    )
    return f"NOT CONVERGED ({polish}; {spent})"


@lru_cache(maxsize=1)
def _schema_validator():
    """The validator of the model file's JSON Schema (``fricid/schemas/model.schema.json``)."""
    from importlib.resources import files

    from jsonschema import Draft202012Validator

    text = files("fricid").joinpath("schemas", "model.schema.json").read_text(encoding="utf-8")
    return Draft202012Validator(json.loads(text))


#: Messages for the size limits of the schema (jsonschema's would print the whole value).
_LIMITS = {
    "maxLength": "text longer than {} characters",
    "maxItems": "more than {} items",
    "maxProperties": "more than {} properties",
}


def _validate_schema(d: dict[str, Any], source: str | None) -> None:
    """Raise a :class:`DataError` naming the file and the first failing field (the schema
    describes every version this fricid reads; the message names the document's)."""
    from jsonschema.exceptions import best_match

    _check_sizes(d, _schema_validator().schema, source)
    # the first errors suffice to name one; a hostile file may have millions
    error = best_match(itertools.islice(_schema_validator().iter_errors(d), 1000))
    if error is None:
        return
    where = one_line("/".join(str(p) for p in error.absolute_path) or "(top level)")[:120]
    message = _LIMITS.get(error.validator, "").format(error.validator_value)
    if not message:
        message = one_line(error.message)
        message = message if len(message) <= 200 else message[:197] + "..."
    version = d.get("schema_version")
    version = version if isinstance(version, int) and 0 < version <= SCHEMA_VERSION else None
    raise DataError(
        f"field '{where}' does not match the model file schema (version "
        f"{version or SCHEMA_VERSION}): "
        f"{message}",
        file=source,
    )


def _max_items(schema: Any) -> int | None:
    """The largest ``maxItems`` a field's schema allows an array (over ``oneOf``/``anyOf``/
    ``allOf`` alternatives); None when an alternative sets no limit."""
    if not isinstance(schema, dict):
        return None
    alternatives = [a for k in ("oneOf", "anyOf") for a in schema.get(k, [])]
    if alternatives:
        limits = [_max_items(a) for a in alternatives if a.get("type") != "null"]
        return None if not limits or None in limits else max(limits)
    limits = [_max_items(a) for a in schema.get("allOf", [])] + [schema.get("maxItems")]
    known = [x for x in limits if isinstance(x, int)]
    return min(known) if known else None


def _check_sizes(d: Any, schema: Any, source: str | None, path: str = "", depth: int = 0) -> None:
    """The schema's array size limits on the named fields, checked before the schema's own
    walk, which descends into every item first (a 1500 x 1500 covariance took it 31 s to
    refuse): a :class:`DataError` naming the field, as :func:`_validate_schema` would."""
    if not isinstance(d, dict) or not isinstance(schema, dict) or depth > 3:
        return
    props = schema.get("properties") or {}
    for name, sub in props.items():
        value = d.get(name)
        where = f"{path}/{name}" if path else name
        limit = _max_items(sub)
        if isinstance(value, list) and limit is not None and len(value) > limit:
            raise DataError(
                f"field '{where}' does not match the model file schema (version "
                f"{SCHEMA_VERSION}): {_LIMITS['maxItems'].format(limit)}",
                file=source,
            )
        if isinstance(value, dict):
            alts = [sub] + [a for k in ("oneOf", "anyOf") for a in sub.get(k, [])]
            for alt in alts:
                _check_sizes(value, alt, source, where, depth + 1)


def _probe_inputs(operating_range: dict[str, list[float]]) -> np.ndarray:
    """Inputs (n, 3) on which loading evaluates a model: see ``_check_predictions``."""
    axes = []
    for name in INPUTS:
        span = operating_range.get(name)
        if span is None:
            axes.append(_PROBE_VELOCITY if name == "velocity" else _PROBE_DEFAULT[name])
            continue
        low, high = float(span[0]), float(span[1])
        points = {low, high, low / 2 + high / 2}
        if low < 0 < high:
            points.add(0.0)
        axes.append(sorted(points))
    return np.array(list(itertools.product(*axes)), dtype=float)
