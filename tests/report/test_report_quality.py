"""The report's data-quality table shows every set-point's label and fate."""

from __future__ import annotations

import warnings

from _sweeps import sweep_log
from fricid.errors import DataQualityWarning
from fricid.extract import extract
from fricid.report.trust import quality_frame


def test_quality_table_names_every_row_and_its_reason():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DataQualityWarning)
        r = extract(sweep_log([0.4, 0.8], extra=[(1e-5, 5.0)]), gravity="joint")
    frame = quality_frame(r.samples.meta["quality"])
    points = frame[frame["kind"] == "setpoint"]
    assert len(points) == 4 and (points["set-point"] != "").all()
    assert (points["what and why"] == "1 run").all()
    assert points["gravity residual [N m]"].notna().all()
    rest = frame[frame["kind"] == "rest"]
    assert rest["what and why"].str.startswith("dropped as standstill").all() and len(rest) == 1
