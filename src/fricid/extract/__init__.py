"""Raw joint logs to friction samples (BAS-RBFNN paper, section 2; RWSAVSBAS paper, 2.1).

>>> from fricid.extract import extract
>>> result = extract(logs, positions=centres, gravity="fit")     # doctest: +SKIP
>>> result.samples, result.by_direction, result.gravity          # doctest: +SKIP

Modules: :mod:`.segment` (constant-velocity segments, set-point clustering), :mod:`.bins`
(position bins, repetition averaging), :mod:`.gravity` (eq. 7 and 11), :mod:`.pipeline`
(:func:`extract`).
"""

from __future__ import annotations

from .bins import Cells, CellTable, Pooled, PositionBins, pool_cells
from .gravity import GravityFit, fit_gravity, separate
from .pipeline import GRAVITY_MODES, SPIKE_SIGMAS, Diagnostics, ExtractionResult, extract
from .segment import Segment, SegmentCounts, cluster, iter_segments

__all__ = [
    "GRAVITY_MODES",
    "SPIKE_SIGMAS",
    "CellTable",
    "Cells",
    "Diagnostics",
    "ExtractionResult",
    "GravityFit",
    "Pooled",
    "PositionBins",
    "Segment",
    "SegmentCounts",
    "cluster",
    "extract",
    "fit_gravity",
    "iter_segments",
    "pool_cells",
    "separate",
]
