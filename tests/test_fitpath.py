"""Issue 14, speed of the default paths: the numba cache across processes, the compiled
kernels of the built-in models, the default ``lm``'s single start, GA's clones."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"

#: A second process running RWSAVSBAS's compiled path: prints the cache statistics of the
#: compiled outer iteration and of the kernel's function pointer.
_CHILD = """
import json, numpy as np
from fricid.experiments.stribeck_problem import StribeckProblem, sse_objective
from fricid.optim import minimize_runs
from fricid.optim import _rws_numba
v = np.linspace(-1.0, 1.0, 17)
problem = StribeckProblem(v, np.sign(v) * 0.3 + 0.01 * v)
minimize_runs(sse_objective(problem, jit=True), problem.bounds, "rwsavsbas", seed=0, runs=2,
              options={"n_outer": 1, "n_inner": 2})
stats = _rws_numba.outer_iteration.stats
print(json.dumps({"hits": sum(stats.cache_hits.values()),
                  "misses": sum(stats.cache_misses.values())}))
"""


def _child() -> dict:
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    out = subprocess.run(
        [sys.executable, "-c", _CHILD], env=env, capture_output=True, text=True, check=True
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_a_second_process_loads_the_compiled_path_from_the_cache():
    """The first process may compile (cold cache); the second must only load: numba typed
    the kernel argument by its memory address before, so every process recompiled."""
    pytest.importorskip("numba")
    _child()
    second = _child()
    assert second == {"hits": 1, "misses": 0}
