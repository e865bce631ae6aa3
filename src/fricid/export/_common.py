"""Shared pieces of the exporters: the error for what a target cannot hold, provenance text."""

from __future__ import annotations

import math

from .. import __version__
from ..errors import ConfigError
from ..fitted import FittedModel

__all__ = ["ExportError", "describe_model", "fmt_float"]


class ExportError(ConfigError):
    """The export target cannot represent the model (the message says what would be lost)."""


def fmt_float(value: float) -> str:
    """A float written so that it reads back bit for bit (``repr``, 17 significant digits)."""
    value = float(value)
    if not math.isfinite(value):
        raise ExportError(f"cannot export the non-finite value {value!r}")
    return repr(value)


def describe_model(fitted: FittedModel, source: str | None = None) -> list[str]:
    """Lines of provenance for a comment at the top of an exported file."""
    prov = fitted.provenance or {}
    lines = [
        f"fricid {__version__} export of the model '{fitted.model}'"
        + (f" from {source}" if source else ""),
        f"identified by {fitted.method or 'unknown method'} (seed {fitted.seed}) from "
        f"{prov.get('source') or 'unrecorded data'}"
        + (f", {prov['n_samples']} samples" if prov.get("n_samples") is not None else ""),
    ]
    if fitted.metrics:
        m = fitted.metrics
        parts = [
            f"{k} {m[k]:.4g}"
            for k in ("fitness", "rmse", "max_abs_error")
            if isinstance(m.get(k), int | float)
        ]
        if parts:
            lines.append("fit on its data: " + ", ".join(parts) + " (rmse, max error in N m)")
    return lines
