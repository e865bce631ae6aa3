"""``bench_verdicts.py --cli-check K``: the same verdict from the API, ``fricid fit`` +
``fricid report`` and the fleet, on the same samples.

The samples of a case are written as a table of means, the form both the CLI (a samples CSV,
:func:`fricid.io.write_samples`) and the fleet (a MATLAB file of means read by the manifest's
``mat`` reader) take: velocity, friction, load and temperature (load 0 N m and 25 degC where
the case measures neither, since a table of means of the fleet always has the columns it is
given), no std or count (a table of means carries none). The API, the CLI and the fleet are
then run on exactly these samples, so their verdicts and ratios must agree to the digit.
A failed fit is one outcome, however it shows (the API raises, the CLI exits 2, the fleet's
row fails); a manifest that does not take the model (the fleet has no ``auto``) shows so.
"""

from __future__ import annotations

import re
import tempfile
import warnings
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["cli_check"]

_TRUST = re.compile(r"Trust: (yes|with caveats|no)\b")
_VARS = "velocity=v;friction=f;load=l;temperature=T"
_UNITS = "velocity=rad/s;friction=N m;load=N m;temperature=degC"


def _means(samples):
    """The case's samples as a table of means (module notes)."""
    from fricid.samples import FrictionSamples

    n = len(samples)
    load = samples.load if np.isfinite(samples.load).all() else np.zeros(n)
    temp = samples.temperature if np.isfinite(samples.temperature).all() else np.full(n, 25.0)
    return FrictionSamples(
        velocity=samples.velocity,
        load=load,
        temperature=temp,
        friction=samples.friction,
        direction=np.sign(samples.velocity),
    )


def _level(text: str) -> str | None:
    found = _TRUST.findall(text or "")
    return found[-1] if found else None


def _outcome(level: str | None) -> str:
    """A verdict, or ``failed`` for an error, a non-zero exit or a failed fleet row."""
    known = ("yes", "with caveats", "no")
    return level if level in known else "failed"


def _cli(app, args: list[str]) -> tuple[int, str]:
    from typer.testing import CliRunner

    res = CliRunner().invoke(app, args)
    text = res.output + (getattr(res, "stderr", "") if res.stderr_bytes is not None else "")
    return res.exit_code, text


def _one(case, model: str, folder: Path) -> dict[str, Any]:
    """API, CLI (fit then report) and fleet verdicts of ``model`` on ``case``'s means."""
    import scipy.io

    from fricid.cli import app
    from fricid.fleet import SerialExecutor, run_fleet
    from fricid.identify import fit
    from fricid.identify.trust import assess_trust
    from fricid.io import write_samples

    s = _means(case.samples)
    csv = folder / "samples.csv"
    write_samples(s, csv)
    scipy.io.savemat(
        folder / "means.mat",
        {"v": s.velocity, "f": s.friction, "l": s.load, "T": s.temperature},
    )
    row: dict[str, Any] = {"case": case.id, "class": case.klass, "model": model}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            fitted = fit(s, model)
            trust = assess_trust(fitted, s)
            row["api"], row["api_ratio"] = trust.level, float(trust.heldout_ratio)
        except Exception as err:
            row["api"], row["api_ratio"] = f"error: {type(err).__name__}", float("nan")
    out = folder / "model.json"
    code, text = _cli(app, ["fit", str(csv), "-m", model, "-o", str(out), "-q"])
    row["cli_fit"] = _level(text) if code == 0 else f"exit {code}"
    if code == 0:
        code, text = _cli(app, ["report", str(out), str(csv), "-o", str(folder / "report")])
        row["cli_report"] = _level(text) if code == 0 else f"exit {code}"
    else:
        row["cli_report"] = row["cli_fit"]
    (folder / "fleet.csv").write_text(
        "robot,joint,log,reader,model,variables,units\n"
        f'r,j{case.id},means.mat,mat,{model},{_VARS},"{_UNITS}"\n',
        encoding="utf-8",
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            run = run_fleet(folder / "fleet.csv", folder / "fleet", executor=SerialExecutor())
            tab = run.table
            row["fleet"] = str(tab["trust"].iloc[0]) if "trust" in tab else "failed"
            ratio = tab["heldout_ratio"].iloc[0] if "heldout_ratio" in tab else None
            row["fleet_ratio"] = float(ratio) if ratio is not None else float("nan")
        except Exception as err:
            row["fleet"], row["fleet_ratio"] = f"error: {type(err).__name__}", float("nan")
    levels = {_outcome(row[k]) for k in ("api", "cli_fit", "cli_report", "fleet")}
    same_ratio = np.isclose(row["api_ratio"], row["fleet_ratio"], rtol=1e-6, equal_nan=True)
    row["agree"] = len(levels) == 1 and bool(same_ratio)
    return row


def cli_check(cases: list, models: tuple[str, ...]) -> list[dict[str, Any]]:
    """Run each case through the API, the CLI and the fleet for each model (module notes)."""
    rows = []
    for case in cases:
        for model in models:
            with tempfile.TemporaryDirectory() as tmp:
                rows.append(_one(case, model, Path(tmp)))
    return rows
