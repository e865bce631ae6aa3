"""Read model files of an earlier layout: version 1 to the current layout (version 2).

Version 1 kept each parameter in ten objects keyed by name (``params``, ``units``, ``stderr``,
``ci95``, ``ci95_low``, ``ci95_high``, ``ci_open``, ``init``, ``bounds``,
``uncertainty_note``) and two lists (``fixed``, ``at_bound``), and the optimiser's
``status``, ``message`` and ``nfev`` both at the top level and in ``convergence``. Version 2
holds one record per parameter under ``parameters`` and the optimiser's record once, under
``optimizer`` (:mod:`fricid.fitted._parameter`); ``convergence`` keeps the verdict.

:func:`upgrade` works on the parsed document after the schema check of its own version, so
every value has the type that version gives it. The correlation matrix of version 1 has its
rows in the order of ``stderr``; version 2 in the order of the free parameters, and rows in
another order are permuted to it.
"""

from __future__ import annotations

from typing import Any

from ..errors import DataError

__all__ = ["upgrade"]

#: Keys of a version-1 file that hold parameters.
PARAMETER_KEYS_1 = (
    "params",
    "units",
    "fixed",
    "stderr",
    "ci95",
    "at_bound",
    "bounds",
    "init",
    "ci95_low",
    "ci95_high",
    "ci_open",
    "uncertainty_note",
)
#: Keys of a version-1 file that hold the optimiser's record.
OPTIMIZER_KEYS_1 = ("method", "seed", "nfev", "history", "status", "message")
#: Keys of a version-1 convergence block that belong to the optimiser's record.
CONVERGENCE_RUN_KEYS_1 = ("status", "message", "nfev", "max_evals")


def upgrade(d: dict[str, Any], source: str | None = None) -> dict[str, Any]:
    """The document ``d`` of version 1 in the current layout (a new dict; ``d`` is left as
    it is).

    Raises
    ------
    DataError
        A search bound whose minimum exceeds its maximum (named as version 1 names it).
    """
    for name, (low, high) in (d.get("bounds") or {}).items():
        if low > high:
            raise DataError(
                f"field 'bounds/{name}': the minimum {low!r} exceeds the maximum {high!r}",
                file=source,
            )
    conv = d.get("convergence")
    out = {k: v for k, v in d.items() if k not in PARAMETER_KEYS_1 + OPTIMIZER_KEYS_1}
    out["schema_version"] = 2
    out["parameters"] = _parameters(d)
    out["optimizer"] = {
        "method": d.get("method", ""),
        "seed": d.get("seed"),
        "status": d.get("status"),
        "message": d.get("message", ""),
        "nfev": d.get("nfev", 0),
        "max_evals": conv.get("max_evals") if isinstance(conv, dict) else None,
        "history": d.get("history"),
    }
    if isinstance(conv, dict):
        out["convergence"] = _verdict(conv)
    if d.get("correlation"):
        free = [n for n, p in out["parameters"].items() if not p["fixed"]]
        out["correlation"] = _reordered(d["correlation"], list(d.get("stderr") or {}), free)
    return out


def _parameters(d: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """The version-2 records of a version-1 document's parameters, in the order of
    ``params``; without ``not_determined``, which the reader judges as version 1 was read
    (:meth:`fricid.fitted.Parameter.from_dict`)."""

    def per(key: str) -> dict[str, Any]:
        return d.get(key) or {}

    fixed, at_bound = set(d.get("fixed") or ()), set(d.get("at_bound") or ())
    units, init, bounds = per("units"), per("init"), per("bounds")
    stderr, half, notes = per("stderr"), per("ci95"), per("uncertainty_note")
    low, high, sides = per("ci95_low"), per("ci95_high"), per("ci_open")
    out = {}
    for name, value in d["params"].items():
        low_open, high_open = sides.get(name) or (False, False)
        out[name] = {
            "value": value,
            "unit": str(units.get(name, "")),
            "fixed": name in fixed,
            "init": init.get(name),
            "bounds": bounds.get(name),
            "stderr": stderr.get(name),
            "ci95": [low.get(name), high.get(name)],
            "ci95_halfwidth": half.get(name),
            "low_open": bool(low_open),
            "high_open": bool(high_open),
            "note": str(notes.get(name, "")),
            "at_bound": name in at_bound,
        }
    return out


def _verdict(conv: dict[str, Any]) -> dict[str, Any]:
    """A version-1 convergence block without the optimiser's record; a block that says it did
    not converge without a reason keeps its message as the reason."""
    out = {k: v for k, v in conv.items() if k not in CONVERGENCE_RUN_KEYS_1}
    if not conv.get("converged") and "reason" not in conv and conv.get("message"):
        out["reason"] = conv["message"]
    return out


def _reordered(corr: list[list[Any]], rows: list[str], free: list[str]) -> list[list[Any]]:
    """The correlation matrix with rows and columns in the order ``free`` (the matrix as it
    is when ``rows`` are not the free parameters in another order)."""
    square = len(corr) == len(rows) and all(len(row) == len(rows) for row in corr)
    if rows == free or sorted(rows) != sorted(free) or not square:
        return corr
    index = [rows.index(n) for n in free]
    return [[corr[i][j] for j in index] for i in index]
