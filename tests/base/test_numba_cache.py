"""Compiled kernels without a writable cache directory (issue 25): a read-only install with an
unwritable home directory made every ``fit`` die with ``RuntimeError: cannot cache function
'_sign': no locator available``. :mod:`fricid._jit` compiles in memory instead.

The condition is simulated without file permissions (root writes through them): numba's
locators are cut down to the user-provided cache directory, and ``NUMBA_CACHE_DIR`` names a
path under a regular file, which no locator can create.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numba
import pytest

from _paths import SRC
from fricid import _jit

#: Every module that compiles a kernel (imported, and one kernel of each family called).
KERNEL_MODULES = (
    "fricid.models._kernels",
    "fricid.models._lugre_kernel",
    "fricid.models._dahl_kernel",
    "fricid.optim._rws_numba",
    "fricid.control._kernels",
    "fricid.identify.learned._kmeans_kernel",
    "fricid.experiments.stribeck_problem",
)

#: Run in a child process: numba without a cache locator, then fricid's kernels.
CHILD = textwrap.dedent(
    """
    import importlib, sys
    import numba
    import numba.core.caching as caching

    impl = getattr(caching, "CacheImpl", None) or caching._CacheImpl
    impl._locator_classes = [caching.UserProvidedCacheLocator]

    def probe(x):
        return x + 1

    try:  # the condition holds: numba itself cannot cache here
        numba.njit(cache=True)(probe)
    except RuntimeError as exc:
        assert "no locator available" in str(exc), exc
    else:
        raise SystemExit("numba found a cache directory: the condition is not simulated")
    for name in sys.argv[1:]:
        importlib.import_module(name)
    from fricid.models._kernels import _sign
    assert _sign(-2.0) == -1.0 and _sign(0.0) == 0.0
    print("ok")
    """
)


def _unwritable_env(tmp_path: Path) -> dict[str, str]:
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("a file where numba wants its cache folder\n")
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env.update(
        NUMBA_CACHE_DIR=str(blocker / "cache"),
        PYTHONPATH=os.pathsep.join([str(SRC), env.get("PYTHONPATH", "")]).rstrip(os.pathsep),
    )
    return env


@pytest.mark.slow  # 5 s measured under load (default run kept short)
def test_kernels_compile_in_memory_without_a_cache_directory(tmp_path):
    res = subprocess.run(
        [sys.executable, "-c", CHILD, *KERNEL_MODULES],
        env=_unwritable_env(tmp_path),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert res.returncode == 0 and res.stdout.strip() == "ok", res.stderr[-2000:]


def _define(source: str):
    """A function whose source file does not exist (so numba has no cache locator for it)."""
    scope: dict = {}
    exec(compile(textwrap.dedent(source), "<generated>", "exec"), scope)
    return scope["twice"]


def test_njit_falls_back_where_numba_cannot_cache():
    twice = _define("def twice(x):\n    return 2 * x\n")
    with pytest.raises(RuntimeError, match="cannot cache"):
        numba.njit(cache=True)(twice)
    assert _jit.njit(cache=True)(twice)(21) == 42
    assert _jit.njit(twice)(1.5) == 3.0  # bare, as numba.njit
    sig = numba.types.float64(numba.types.float64)
    assert _jit.cfunc(sig, cache=True)(twice).ctypes(4.0) == 8.0


def test_other_errors_are_not_swallowed(monkeypatch):
    def broken(**_options):
        raise RuntimeError("something else went wrong")

    monkeypatch.setattr(_jit.numba, "njit", broken)
    with pytest.raises(RuntimeError, match="something else"):
        _jit.njit(cache=True)(lambda x: x)


@pytest.mark.slow
def test_fit_runs_without_a_cache_directory(tmp_path):
    """The command the issue saw die: ``fricid fit`` with a compiled optimiser."""
    from fricid.extract import extract
    from fricid.io import write_samples
    from fricid.sim import preset, simulate

    samples = extract(simulate(preset("paper2", "quick"), seed=0), gravity="none").samples
    path = write_samples(samples, tmp_path / "s.csv")
    child = textwrap.dedent(
        """
        import sys
        import numba.core.caching as caching
        impl = getattr(caching, "CacheImpl", None) or caching._CacheImpl
        impl._locator_classes = [caching.UserProvidedCacheLocator]
        from fricid.cli import main
        sys.argv = ["fricid", *sys.argv[1:]]
        main()
        """
    )
    args = ["fit", str(path), "--model", "stribeck", "--fix", "delta=1", "--method", "bas"]
    res = subprocess.run(
        [sys.executable, "-c", child, *args, "--max-evals", "400", "--out", str(tmp_path / "m")],
        env=_unwritable_env(tmp_path),
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert res.returncode == 0, res.stderr[-2000:]
    assert "cannot cache" not in res.stderr
