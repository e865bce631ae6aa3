"""What every identified model file records of its data: provenance and operating range."""

from __future__ import annotations

from typing import Any

import numpy as np

from .. import __version__
from ..io.atomic import created_timestamp
from ..models import INPUTS
from ..models._range import speed_coverage
from ..samples import FrictionSamples, row_digests, samples_hash

__all__ = ["ROW_DIGESTS_MAX", "operating_range", "provenance"]

#: Samples up to this many keep one digest per row in the provenance (``rows_sha256_12``,
#: sorted): a report on other samples tells the model's own rows among them, whatever their
#: order (:func:`fricid.identify._heldout.is_new_samples`); larger sets keep the set's hash only.
ROW_DIGESTS_MAX = 5000


def provenance(samples: FrictionSamples, **extra: Any) -> dict[str, Any]:
    """Source, size, hash, directions, the measured speeds per direction with the gaps
    between them (``speeds``: :func:`fricid.models._range.speed_coverage`), version and time
    of ``samples`` (plus ``extra``)."""
    return {
        "source": samples.source,
        "n_samples": len(samples),
        "samples_sha256_16": samples_hash(samples),
        **(
            {"rows_sha256_12": sorted(row_digests(samples).tolist())}
            if len(samples) <= ROW_DIGESTS_MAX
            else {}
        ),
        "directions": list(samples.directions()),
        "speeds": speed_coverage(samples.velocity, samples.directions()),
        "fricid_version": __version__,
        "created": created_timestamp(),
        **extra,
    }


def operating_range(samples: FrictionSamples, X: np.ndarray | None = None) -> dict[str, list]:
    """Min and max of each measured input (columns of ``X``, default ``samples.X``)."""
    X = samples.X if X is None else X
    return {
        name: [float(X[:, j].min()), float(X[:, j].max())]
        for j, name in enumerate(INPUTS)
        if name in samples.measured
    }
