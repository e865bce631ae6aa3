"""The report's load and temperature bands (:func:`fricid.report.style.band_edges`): every
sample lies in exactly one band, NaN ones (not measured) in a band of their own, which the
panels name as such rather than "load nan–nan"."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fricid.report.interactive import _band_cells
from fricid.report.style import band_edges, in_band
from fricid.samples import FrictionSamples

values = st.lists(
    st.one_of(st.floats(-1e3, 1e3, allow_nan=False), st.just(float("nan"))), max_size=40
)


@settings(max_examples=150, deadline=None)
@given(values, st.integers(1, 5))
def test_every_value_lies_in_exactly_one_band(xs, max_bands):
    x = np.array(xs, dtype=float)
    bands = band_edges(x, max_bands)
    hits = np.sum([in_band(x, b) for b in bands], axis=0) if bands else np.zeros(x.size)
    assert np.all(hits == 1)
    assert len(bands) <= max_bands + 1  # the finite bands, and one of NaN
    assert all(np.isnan(b[0]) == np.isnan(b[1]) for b in bands)


def test_a_log_without_load_gets_no_load_title(monkeypatch):
    """No load channel: one band of NaN, and no panel title (it read "load nan–nan N m")."""
    from fricid.report import plots

    monkeypatch.setattr(plots, "png", lambda fig: fig)  # the figure, not its PNG
    v = np.r_[np.geomspace(0.01, 1.0, 6), -np.geomspace(0.01, 1.0, 6)]
    samples = FrictionSamples(
        velocity=v, load=None, temperature=25.0, friction=np.sign(v) * (0.2 + 0.05 * np.abs(v))
    )
    assert np.isnan(samples.load).all()
    fig = plots.friction_curves(samples, lambda X: np.sign(X[:, 0]) * 0.2)
    titles = [ax.get_title() for ax in fig.axes]
    assert not any("nan" in t or "load" in t for t in titles), titles
    cells, _, _ = _band_cells(samples, 3)
    assert not any("nan" in label for *_, label in cells)
