"""A lean start: the command line loads the heavy libraries only in the commands that use them.

``import fricid.cli``, building the whole application (every sub-command registered, as
``fricid --help`` does), ``fricid --help`` itself and ``fricid predict`` on a model file run in a
fresh interpreter each; none of them may have imported the modules listed in :data:`HEAVY`.
(``benchmarks/bench_startup.py`` measures the CPU time against importing numpy and pandas.)
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from _paths import SRC
from fricid.errors import FricidWarning
from fricid.identify import fit
from fricid.samples import FrictionSamples

#: Modules that the start of the command line must not load.
HEAVY = (
    "scipy.stats",
    "scipy.optimize",
    "scipy.fft",
    "matplotlib",
    "sklearn",
    "dask",
    "plotly",
    "cma",
    "h5py",
    "rosbags",
    "numba",
)

#: Runs ``body`` (which may raise SystemExit), then prints the heavy modules loaded, as JSON.
SCRIPT = """
import json, sys
try:
{body}
except SystemExit:
    pass
sys.stdout.write("\\nLOADED " + json.dumps([m for m in {heavy!r} if m in sys.modules]) + "\\n")
"""


def loaded(body: str) -> list[str]:
    """The modules of :data:`HEAVY` loaded after ``body`` runs in a fresh interpreter."""
    code = SCRIPT.format(body="\n".join("    " + line for line in body.splitlines()), heavy=HEAVY)
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120
    )
    lines = [line for line in out.stdout.splitlines() if line.startswith("LOADED ")]
    assert lines, f"the script did not finish: {out.stderr[-2000:]}"
    return json.loads(lines[-1][len("LOADED ") :])


def test_import_fricid_cli_is_lean():
    assert loaded("import fricid.cli") == []


def test_building_every_command_is_lean():
    body = "import fricid.cli\nfrom typer.main import get_command\nget_command(fricid.cli.app)"
    assert loaded(body) == []


def test_help_is_lean():
    assert loaded("from fricid.cli._app import main\nmain(['--help'])") == []


@pytest.fixture
def model_path(tmp_path: Path) -> Path:
    v = np.repeat(np.linspace(0.1, 2.0, 6), 2) * np.tile([1.0, -1.0], 6)
    samples = FrictionSamples(
        velocity=v, load=0.0, temperature=25.0, friction=np.sign(v) * 0.4 + 0.1 * v
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FricidWarning)
        fitted = fit(samples, "coulomb_viscous")
    path = tmp_path / "model.json"
    fitted.save(path)
    return path


def test_predict_is_lean(model_path: Path):
    body = f"from fricid.cli._app import main\nmain(['predict', {str(model_path)!r}, '-v', '0.5'])"
    assert loaded(body) == []
