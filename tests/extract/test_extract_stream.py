"""Extraction at the read floor: the same results from faster code.

The settled level of a run's velocity is found on the sorted block means (O(k log k)) instead of
a k x k matrix of their distances; the test keeps the matrix version as the reference and holds
the two to the same answer, bit for bit, on random, tied and quantised inputs.
"""

from __future__ import annotations

import itertools
import weakref
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.ndimage import median_filter as scipy_median_filter

from fricid.errors import DataError
from fricid.extract._stats import far_from_running_median
from fricid.extract._stats import median as fast_median
from fricid.extract._stats import median_filter as fast_median_filter
from fricid.extract._stats import percentile as fast_percentile
from fricid.extract.steady import _ends, _near_windows, _velocity_ends, robust_scale, saturated
from fricid.samples import RawLog


def _velocity_ends_matrix(means: np.ndarray, floor: float, sigmas: float) -> tuple[int, int]:
    """The k x k reference: every pair of block means compared."""
    near = np.abs(means[:, None] - means[None, :]) <= 2.0 * floor
    centre = int(np.argmax(near.sum(axis=1)))
    cluster = means[near[centre]]
    level = float(np.median(cluster))
    scale = max(robust_scale(cluster), floor)
    return _ends(np.abs(means - level) / scale, sigmas)


def _windows_matrix(s: np.ndarray, width: float) -> tuple[np.ndarray, np.ndarray]:
    near = np.abs(s[None, :] - s[:, None]) <= width
    return near.argmax(axis=1), s.size - near[:, ::-1].argmax(axis=1)


_finite = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False, width=64)


@st.composite
def _means(draw) -> np.ndarray:
    """Block means: a settled level with noise, ramps, ties and quantisation mixed in."""
    k = draw(st.integers(1, 120))
    kind = draw(st.sampled_from(["free", "settled", "quantised", "ties"]))
    if kind == "free":
        return np.array(draw(st.lists(_finite, min_size=k, max_size=k)))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    level = draw(_finite)
    noise = draw(st.sampled_from([0.0, 1e-12, 1e-3, 1.0]))
    x = level + noise * rng.standard_normal(k)
    ramp = draw(st.integers(0, k))
    x[:ramp] += np.linspace(draw(_finite), 0.0, ramp)
    if kind == "quantised":
        step = draw(st.sampled_from([1e-3, 0.1, 2.0**-20]))
        x = np.round(x / step) * step
    if kind == "ties":
        x = rng.choice(x[: max(1, k // 4)], size=k)
    return x


@settings(max_examples=200, deadline=None)
@given(_means(), st.sampled_from([1e-12, 1e-3, 0.05, 0.5, 3.0]), st.sampled_from([2.0, 5.0]))
def test_velocity_ends_sorted_matches_matrix(means, floor, sigmas):
    # the floor is also drawn relative to the data (a width landing on exact gaps)
    for f in (floor, max(floor * float(np.ptp(means)), floor)):
        assert _velocity_ends(means, f, sigmas) == _velocity_ends_matrix(means, f, sigmas)


@settings(max_examples=150, deadline=None)
@given(_means(), st.sampled_from([0.0, 1e-12, 1e-3, 0.1, 1.0, 7.0]))
def test_near_windows_match_the_pairwise_test(means, width):
    s = np.sort(means)
    lo, hi = _near_windows(s, width)
    ref_lo, ref_hi = _windows_matrix(s, width)
    np.testing.assert_array_equal(lo, ref_lo)
    np.testing.assert_array_equal(hi, ref_hi)


@pytest.mark.parametrize(("a", "b", "width"), [(0.828, 1.238, 0.41), (0.33, 1.12, 0.79)])
def test_near_windows_at_an_ulp_boundary(a, b, width):
    # a + width and b - width round differently from b - a: searchsorted alone is off by one
    exact = abs(b - a) <= width
    assert not (b <= a + width) == exact == (a >= b - width)
    s = np.array([a, a, b, b])
    lo, hi = _near_windows(s, width)
    ref_lo, ref_hi = _windows_matrix(s, width)
    assert (lo.tolist(), hi.tolist()) == (ref_lo.tolist(), ref_hi.tolist())


_samples = st.lists(
    st.one_of(_finite, st.sampled_from([0.0, -0.0, 1.0, -1.0, 1e-300])), min_size=1, max_size=60
)


def _bits(x: float) -> int:
    return int(np.float64(x).view(np.uint64))


@settings(max_examples=300, deadline=None)
@given(_samples)
def test_median_is_numpys_bit_for_bit(values):
    x = np.array(values)
    assert _bits(fast_median(x)) == _bits(np.median(x))


@settings(max_examples=300, deadline=None)
@given(_samples)
def test_median_in_place_is_numpys_bit_for_bit(values):
    """Partitioned in place (the segmentation's time steps): the same value, zeros' signs
    included, and the same values left in the array, reordered."""
    x = np.array(values)
    expected = np.median(x)
    assert _bits(fast_median(x, overwrite=True)) == _bits(expected)
    np.testing.assert_array_equal(np.sort(x), np.sort(np.array(values)))


@settings(max_examples=300, deadline=None)
@given(_samples, st.sampled_from([0.0, 1.0, 25.0, 50.0, 99.0, 99.9, 100.0]))
def test_percentile_is_numpys_bit_for_bit(values, q):
    x = np.array(values)
    assert _bits(fast_percentile(x, q)) == _bits(np.percentile(x, q))


@settings(max_examples=100, deadline=None)
@given(_samples, st.sampled_from([1, 3, 5, 7, 31, 61]))
def test_median_filter_is_scipys_bit_for_bit(values, size):
    x = np.array(values)
    ours = fast_median_filter(x, size)
    theirs = scipy_median_filter(x, size=size, mode="nearest")
    np.testing.assert_array_equal(ours.view(np.uint64), theirs.view(np.uint64))


def test_median_filter_long_quantised_signal():
    # a long, quantised, noisy torque: many ties, values leaving and entering the window equal
    rng = np.random.default_rng(3)
    x = np.round(
        0.2 + 0.01 * rng.standard_normal(20_000) + 0.05 * np.sin(np.arange(20_000) / 500), 3
    )
    for size in (5, 31):
        ours = fast_median_filter(x, size)
        np.testing.assert_array_equal(ours, scipy_median_filter(x, size=size, mode="nearest"))


@st.composite
def _signals(draw) -> np.ndarray:
    """Torque-like signals: noise around a trend, spikes and steps, quantised or not."""
    n = draw(st.integers(1, 400))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    x = draw(st.sampled_from([0.0, 0.01, 1.0])) * rng.standard_normal(n)
    x += draw(st.sampled_from([0.0, 1e-3])) * np.arange(n) + draw(_finite)
    spikes = rng.random(n) < draw(st.sampled_from([0.0, 0.01, 0.2]))
    x[spikes] += draw(st.sampled_from([0.5, 50.0])) * rng.standard_normal(int(spikes.sum()))
    if draw(st.booleans()):
        x[n // 2 :] += draw(_finite)  # a step
    if draw(st.booleans()):
        x = np.round(x, 2)
    return x


@settings(max_examples=300, deadline=None)
@given(
    st.one_of(_signals(), _samples.map(np.array)),
    st.sampled_from([1, 3, 5, 31, 61]),
    st.sampled_from([0.0, 1e-3, 0.05, 1.0, 8.0, np.inf]),
)
def test_far_from_running_median_is_the_filtered_test(x, size, threshold):
    """Bounded by running minima and maxima, then the candidates' medians: the same mask as
    filtering the whole signal (the outlier screen's second filter)."""
    size = max(min(size, x.size - (1 - x.size % 2)), 1)
    expected = np.abs(x - scipy_median_filter(x, size=size, mode="nearest")) > threshold
    np.testing.assert_array_equal(far_from_running_median(x, size, threshold), expected)


def _saturated_unique(torque: np.ndarray, min_share: float = 0.01, min_count: int = 5):
    """The reference: rails found from ``np.unique`` (sorted values and their counts)."""
    mask = np.zeros(torque.shape, dtype=bool)
    if torque.size < min_count:
        return mask
    need = max(min_count, int(np.ceil(min_share * torque.size)))
    values, counts = np.unique(torque, return_counts=True)
    if values.size < 2:
        return mask
    for rail, n_rail, n_next in (
        (values[-1], counts[-1], counts[-2]),
        (values[0], counts[0], counts[1]),
    ):
        if n_rail >= need and n_rail > 3 * n_next:
            mask |= torque == rail
    return mask


@settings(max_examples=150, deadline=None)
@given(
    st.lists(st.sampled_from([-2.0, -1.0, -0.0, 0.0, 0.5, 1.0, 3.0]), min_size=0, max_size=80),
    st.integers(0, 40),
    st.integers(0, 40),
)
def test_saturated_matches_the_unique_count(values, top, bottom):
    x = np.array(values + [9.0] * top + [-9.0] * bottom)
    np.testing.assert_array_equal(saturated(x), _saturated_unique(x))


def _log(t0: float, n: int, **efforts) -> RawLog:
    t = t0 + 0.01 * np.arange(n)
    return RawLog(time=t, position=0.1 * t, velocity=0.1, temperature=25.0, **efforts)


def test_rawlog_slice_is_a_view_not_checked_again():
    log = _log(0.0, 10, torque=np.ones(10))
    part = log.slice(2, 6)
    assert len(part) == 4 and np.shares_memory(part.time, log.time)
    assert part.torque is not None and part.current is None
    assert part.source == log.source and part.meta == log.meta


def test_rawlog_concatenate_checks_the_junctions():
    a, b = _log(0.0, 5, torque=np.ones(5)), _log(0.05, 5, torque=np.ones(5))
    joined = RawLog.concatenate([a, b])
    np.testing.assert_array_equal(joined.time, np.concatenate([a.time, b.time]))
    with pytest.raises(DataError) as err:
        RawLog.concatenate([a, _log(0.04, 5, torque=np.ones(5))])
    assert err.value.row == 5 and err.value.column == "time"
    # an empty log in between is skipped, not compared
    assert len(RawLog.concatenate([a, a.slice(0, 0), b])) == 10
    # torque in one, current in the other: no effort column survives, which is refused
    with pytest.raises(DataError, match="neither a torque nor a current"):
        RawLog.concatenate([a, _log(0.05, 5, current=np.ones(5), torque_constant=0.5)])


def _segments_joined(chunks, **options):
    """The reference segmentation: each chunk joined to the open run before it is cut."""
    from fricid.extract import segment as sg

    counts = sg.SegmentCounts()
    opts = (options.get("velocity_tolerance", 0.05), options.get("settle_time", 0.1))
    opts = (*opts, options.get("min_samples", 20), counts)
    out, carry, carry_row = [], None, 0
    for chunk in chunks:
        counts.chunks += 1
        counts.rows += len(chunk)
        if len(chunk) == 0:
            continue
        if carry is not None and chunk.time[0] <= carry.time[-1]:
            for found in sg._steady(carry, 0, len(carry), *opts):
                out.append(sg._segment(carry, carry_row, *found))
            carry_row += len(carry)
            carry = None
        buf = chunk if carry is None else RawLog.concatenate([carry, chunk])
        sign = np.sign(buf.velocity)
        sign[np.abs(buf.velocity) <= sg.REST_RESIDUE] = 0.0
        edges = np.flatnonzero(sign[1:] != sign[:-1]) + 1
        if len(buf) > 2:
            dt = np.diff(buf.time)
            edges = np.union1d(edges, np.flatnonzero(dt > sg.GAP_FACTOR * np.median(dt)) + 1)
        starts, stops = np.concatenate(([0], edges)), np.concatenate((edges, [len(buf)]))
        for start, stop in zip(starts[:-1], stops[:-1], strict=True):
            if sign[start] == 0:
                counts.dropped_samples += int(stop - start)
                continue
            for found in sg._steady(buf, int(start), int(stop), *opts):
                out.append(sg._segment(buf, carry_row, *found))
        carry, carry_row = buf.slice(int(starts[-1]), len(buf)), carry_row + int(starts[-1])
    if carry is not None and len(carry) and abs(carry.velocity[0]) > sg.REST_RESIDUE:
        for found in sg._steady(carry, 0, len(carry), *opts):
            out.append(sg._segment(carry, carry_row, *found))
    elif carry is not None:
        counts.dropped_samples += len(carry)
    return out, counts


def _stream_log() -> RawLog:
    """Runs of both signs, rests, float residue, flicker, gaps and a slow clock drift."""
    rng = np.random.default_rng(5)
    parts, t0 = [], 0.0
    for v in (0.5, 0.0, -0.3, 1e-15, 0.8, -0.8, 0.0, 0.2, -0.2):
        n = int(rng.integers(30, 400))
        dt = 0.01 * (1 + 0.2 * rng.random())
        t = t0 + dt * np.arange(n)
        vel = v + 0.002 * rng.standard_normal(n) * (v != 0)
        if rng.random() < 0.5:  # a gap inside the run
            t[n // 2 :] += 0.5
        parts.append((t, vel))
        t0 = t[-1] + dt
    t = np.concatenate([p[0] for p in parts])
    v = np.concatenate([p[1] for p in parts])
    v[rng.integers(0, v.size, 15)] *= -1  # sign flicker
    return RawLog(time=t, position=np.cumsum(v) * 0.01, velocity=v, temperature=25.0, torque=v)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(1, 700), min_size=1, max_size=12), st.booleans())
def test_segments_of_any_chunking_match_the_joined_reference(sizes, restart):
    from fricid.extract.segment import SegmentCounts, iter_segments

    log = _stream_log()
    bounds = np.unique(np.clip(np.cumsum([0, *sizes]), 0, len(log)))
    chunks = [log.slice(a, b) for a, b in itertools.pairwise(bounds)]
    chunks.append(log.slice(int(bounds[-1]), len(log)))
    if restart and len(chunks) > 1:  # the second half's clock restarts: a new file
        k = len(chunks) // 2
        shift = chunks[k].time[0] - 1.0
        chunks[k:] = [replace(c, time=c.time - shift) for c in chunks[k:]]
    counts = SegmentCounts()
    ours = list(iter_segments(chunks, min_samples=10, counts=counts))
    ref, ref_counts = _segments_joined(chunks, min_samples=10)
    assert counts == ref_counts
    assert [(s.row, s.plateau, len(s.log), s.band_fraction) for s in ours] == [
        (s.row, s.plateau, len(s.log), s.band_fraction) for s in ref
    ]
    for a, b in zip(ours, ref, strict=True):
        np.testing.assert_array_equal(a.log.time, b.log.time)


def test_extraction_holds_one_chunk_at_a_time(tmp_path):
    """Memory bounded by one chunk: when a chunk is read, every earlier chunk's columns are
    already freed (no layer of the stream, from the reader to the segmentation, holds one)."""
    from fricid.io import write_rawlog
    from fricid.sim import preset, simulate
    from fricid.workflow import load_joint

    path = write_rawlog(simulate(preset("paper1", "quick"), seed=0), tmp_path / "log.parquet")
    earlier: list[weakref.ref] = []
    alive: list[int] = []

    def watch(chunk: RawLog) -> RawLog:
        alive.append(sum(ref() is not None for ref in earlier))
        earlier.append(weakref.ref(chunk.time))
        return chunk

    data = load_joint(path, chunk_rows=20_000, chunk_map=watch)
    assert data.extraction.diagnostics.chunks == len(earlier) > 3
    assert alive == [0] * len(earlier)
