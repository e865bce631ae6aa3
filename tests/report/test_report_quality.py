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


def test_the_scatter_line_points_at_a_table_only_where_there_is_one():
    import numpy as np

    from fricid.identify import fit
    from fricid.identify.trust import assess_trust
    from fricid.report.trust import trust_text
    from fricid.samples import FrictionSamples

    v = np.r_[np.geomspace(0.05, 2.0, 12), -np.geomspace(0.05, 2.0, 12)]
    rng = np.random.default_rng(0)
    f = np.sign(v) * (0.3 + 0.1 * np.abs(v)) + 0.01 * rng.standard_normal(v.size)
    bare = FrictionSamples(velocity=v, load=None, temperature=None, friction=f, std=0.07, count=50)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        trust = assess_trust(fit(bare, "coulomb_viscous"), bare)
    assert trust.quality is None and np.isfinite(trust.scatter)
    text = trust_text(trust)
    assert "Measurement scatter" in text and "data-quality table" not in text
