"""The C compiler harness every C-export test shares: compile an exported ``fricid_friction.c``
with a ``main`` that reads ``v l T`` lines and prints the friction, run it, read the numbers.

With it, what the C-export tests compare with: :func:`points` to evaluate at, the error
measures (:func:`relative_error` and the scales of rounding in smoothing zones and RBF sums),
and :data:`SMOOTHINGS`. One set of flags for every test (C99, pedantic, every warning an
error); tests that need a C compiler take the ``needs_cc`` mark and are skipped, saying why,
where there is none.
"""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pytest

from fricid.export import Smoothing
from fricid.fitted import FittedModel

CC = shutil.which("cc") or shutil.which("gcc")
needs_cc = pytest.mark.skipif(
    CC is None, reason="no C compiler (cc or gcc) on PATH: optional, not a Python dependency"
)
CFLAGS = [
    "-std=c99",
    "-O2",
    "-Wall",
    "-Wextra",
    "-Wpedantic",
    "-Werror",
    "-Wshadow",
    "-Wconversion",
]

HARNESS = r"""
#include <stdio.h>
#include "fricid_friction.h"
int main(void)
{
    double v, l, t;
    while (scanf("%lf %lf %lf", &v, &l, &t) == 3)
        printf("%.17g\n", fricid_friction(v, l, t));
    return 0;
}
"""


def compile_c(directory: Path, sources: Sequence[str], exe: str = "friction") -> Path:
    """``sources`` (in ``directory``) compiled with :data:`CFLAGS` and libm; the compiler's
    messages are the assertion's when it fails."""
    path = directory / exe
    res = subprocess.run(
        [CC, *CFLAGS, "-o", str(path), *(str(directory / s) for s in sources), "-lm"],
        capture_output=True,
        text=True,
    )
    assert res.returncode == 0, res.stderr
    return path


def compile_and_run(directory: Path, X: np.ndarray) -> np.ndarray:
    """The friction the exported C in ``directory`` computes at the rows ``(v, load, T)`` of
    ``X``, run in ``directory`` (so anything it writes lands there)."""
    (directory / "main.c").write_text(HARNESS)
    exe = compile_c(directory, ("main.c", "fricid_friction.c"))
    text = "\n".join(" ".join(repr(float(x)) for x in row) for row in X)
    run = subprocess.run(
        [str(exe)], input=text, check=True, capture_output=True, text=True, cwd=directory
    )
    return np.array([float(line) for line in run.stdout.split()])


def points(n: int = 3000, seed: int = 0) -> np.ndarray:
    """Velocities over six decades and both signs (zero and the smoothing zone edges
    included), loads of both signs, temperatures 0-50 degC."""
    rng = np.random.default_rng(seed)
    speed = 10.0 ** rng.uniform(-5, 0.7, n)
    v = speed * rng.choice([-1.0, 1.0], n)
    v[:8] = [0.0, -0.0, 0.01, -0.01, 0.02, -0.02, 1e-300, -1e-300]
    return np.column_stack([v, rng.uniform(-0.5, 0.5, n), rng.uniform(0.0, 50.0, n)])


def relative_error(c: np.ndarray, py: np.ndarray, scale: np.ndarray | None = None) -> float:
    """max |c - py| / max(|py|, scale) over points where that is > 1e-12 N m; the others
    must agree to 1e-18 N m."""
    ref = np.abs(py) if scale is None else np.maximum(np.abs(py), scale)
    big = ref > 1e-12
    assert np.all(np.abs(c[~big] - py[~big]) <= 1e-18)
    return float(np.max(np.abs(c[big] - py[big]) / ref[big]))


def zone_scale(fitted: FittedModel, X: np.ndarray, smoothing: Smoothing) -> np.ndarray | None:
    """Inside a linear zone the result is a difference of the model's values at the zone
    edges, which cancel near the crossing of a per-direction model: the error there is
    relative to those values (the conditioning of the formula), elsewhere to the result."""
    if smoothing.kind != "linear":
        return None
    edges = [X.copy(), X.copy()]
    edges[0][:, 0], edges[1][:, 0] = smoothing.zone, -smoothing.zone
    level = np.maximum(*(np.abs(fitted.predict(e)) for e in edges))
    return np.where(np.abs(X[:, 0]) < smoothing.zone, level, 0.0)


SMOOTHINGS = [Smoothing(), Smoothing("tanh", 0.01), Smoothing("linear", 0.02)]


def sum_scale(fitted: FittedModel, X: np.ndarray) -> np.ndarray:
    """sum_j |w_j phi_j(x)| + |b|: the output is a sum of these terms, which cancel where the
    network crosses zero, so this is the scale of its rounding error (the sum's condition)."""
    from fricid.models.rbf import predict_state

    def absolute(net: dict) -> dict:
        return {**net, "weights": np.abs(net["weights"]).tolist(), "bias": abs(net["bias"])}

    state = dict(fitted.state)
    if state.get("symmetry") == "per_direction":
        state.update(pos=absolute(state["pos"]), neg=absolute(state["neg"]))
    else:
        state = absolute(state)
    return np.abs(predict_state(state, X))  # sign(v) g(|v|): the scale is that of g
