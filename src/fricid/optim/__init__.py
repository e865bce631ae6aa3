"""Generic optimisers behind one API (DESIGN.md, "Optimiser API").

``minimize(fun, bounds, method=...)`` with methods registered in :data:`METHODS`. Nothing here
knows about friction: objectives are plain batch functions ``(k, d) -> (k,)``.
"""

from __future__ import annotations

from . import _least_squares  # noqa: F401  (registers lm, trf)
from ._api import METHODS, OptimizeResult, check_bounds, minimize

__all__ = ["METHODS", "OptimizeResult", "check_bounds", "minimize"]
