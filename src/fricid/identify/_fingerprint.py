"""What a trust record was computed on (:mod:`fricid.identify.trust`, "Reuse"): hashes of the
model file and of the samples that survive a JSON round trip, the record made JSON-ready, and
the check of the types of a record read back.
"""

from __future__ import annotations

import hashlib
import json
from typing import Any

import numpy as np

from ..fitted import FittedModel
from ..samples import FrictionSamples, samples_hash
from ._heldout import LEARNED_VALIDATE_WORK, MIN_LEVELS, TINY_SAMPLES, VALIDATE_WORK

__all__ = [
    "canonical",
    "check_record_types",
    "json_ready",
    "model_hash",
    "record_key",
    "samples_detail_hash",
    "trust_options",
]


def json_ready(value: Any) -> Any:
    """``value`` with numpy values as Python ones and non-finite floats as None, recursively."""
    if isinstance(value, dict):
        return {str(k): json_ready(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [json_ready(v) for v in value]
    if isinstance(value, np.ndarray):
        return json_ready(value.tolist())
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, int | np.integer):
        return int(value)
    if isinstance(value, float | np.floating):
        return float(value) if np.isfinite(value) else None
    return value


def canonical(value: Any) -> Any:
    """Numbers as floats (1 and 1.0 alike, as a JSON round trip leaves them), recursively."""
    if isinstance(value, dict):
        return {str(k): canonical(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [canonical(v) for v in value]
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, int | float):
        return float(value)
    return value


def _digest(doc: Any) -> str:
    text = json.dumps(canonical(doc), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


def model_hash(fitted: FittedModel) -> str:
    """A hash of the model file without its ``trust`` and the provenance's source, time,
    version and warnings (what may change after the record is computed, or between two
    copies of the same samples, without changing the model)."""
    d = fitted.to_dict()
    for key in ("trust", "fricid_version", "schema_version"):
        d.pop(key, None)
    d["provenance"] = {
        k: v
        for k, v in (d.get("provenance") or {}).items()
        if k not in ("source", "created", "fricid_version", "warnings")
    }
    return _digest(d)


def samples_detail_hash(samples: FrictionSamples) -> str:
    """A hash of what the scatter, the quality table and the gravity caveats read besides the
    values: count, std and ``meta`` ``sem``, ``sem_method``, ``sem_caveat``, ``setpoint``,
    ``quality``, ``extract``, ``gravity_residual`` and ``channel_problems``."""
    meta = {k: samples.meta.get(k) for k in ("sem", "sem_method", "sem_caveat", "quality")}
    for key in ("setpoint", "extract", "gravity_residual", "channel_problems"):
        if key in samples.meta:
            meta[key] = samples.meta[key]
    doc = {"count": samples.count.tolist(), "std": samples.std.tolist(), "meta": meta}
    return _digest(json.loads(json.dumps(doc, default=_default)))


def _default(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return str(value)


#: The type of each text, list and mapping field of a record read from a file: a record
#: of other types is not used (the report would fail on it).
_TEXT = (
    "level",
    "convergence",
    "advice",
    "heldout_source",
    "heldout_scheme",
    "verdict",
    "scatter_method",
    "validation_note",
    "range",
    "quality_summary",
    "what_to_do",
    "model",
)


def check_record_types(record: Any) -> None:
    """TypeError unless every field of ``record`` (a :class:`fricid.identify.trust.Trust`
    read from a file) has the type the report reads."""

    def texts(value: Any) -> bool:
        return isinstance(value, list) and all(isinstance(v, str) for v in value)

    def rows(value: Any) -> bool:
        return isinstance(value, list) and all(isinstance(v, dict) for v in value)

    ok = [
        record.level in ("yes", "with caveats", "no"),
        all(isinstance(getattr(record, k), str) for k in _TEXT),
        texts(record.reasons) and texts(record.not_determined),
        texts(record.downweighted),
        isinstance(record.open_sides, dict) and texts(list(record.open_sides.values())),
        record.converged is None or isinstance(record.converged, bool),
        isinstance(record.learned, bool) and isinstance(record.options, dict),
        record.quality is None or rows(record.quality),
    ]
    for part in (record.validation, record.cv):
        ok.append(part is None or (isinstance(part, dict) and rows(part.get("folds") or [])))
    if not all(ok):
        raise TypeError("not a trust record of this fricid")


def trust_options(validate: bool = True, max_work: int = VALIDATE_WORK) -> dict[str, Any]:
    """The options a record depends on: whether a validation may be run here and its limits."""
    return {
        "validate": bool(validate),
        "max_work": int(max_work),
        "learned_work": int(LEARNED_VALIDATE_WORK),
        "min_levels": int(MIN_LEVELS),
        "tiny_samples": int(TINY_SAMPLES),
    }


def record_key(
    fitted: FittedModel, samples: FrictionSamples | None, options: dict[str, Any], version: int
) -> dict[str, Any]:
    """What a record of format ``version`` computed with ``options`` was computed on."""
    return {
        "samples_hash": None if samples is None else samples_hash(samples),
        "samples_detail_hash": None if samples is None else samples_detail_hash(samples),
        "model_hash": model_hash(fitted),
        "options": options,
        "version": version,
    }
