"""The report of a whole arm's identification (``fricid report ARM.json``): a row per joint,
rendered from the fit file alone (verdicts, friction, base and standard parameters)."""

from __future__ import annotations

import math

import pandas as pd
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.fitted.arm import ArmFit
from fricid.report import arm_report
from fricid.report.arm import base_table, consistency_note, link_table, verdict_table

runner = CliRunner()

_UNITS = {"f_c": "N m", "beta": "N m s/rad"}


def _friction(f_c: float, beta: float, determined: bool = True) -> dict:
    params = {}
    for name, value in (("f_c", f_c), ("beta", beta)):
        params[name] = {
            "value": value if determined else None,
            "unit": _UNITS[name],
            "stderr": 0.01 if determined else None,
            "ci95": [value - 0.02, value + 0.02] if determined else [None, None],
            "not_determined": not determined,
            "note": "" if determined else "not determined: the joint does not move",
        }
    return {"family": "coulomb_viscous", "parameters": params, "velocity_range": [-2.0, 2.0]}


def _standard() -> dict:
    names, values = [], []
    for joint, m in (("shoulder", 2.0), ("elbow", 0.5)):
        for k, v in zip(
            ("m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz"),
            (m, 0.0, 0.0, 0.2 * m, 0.01, 0.0, 0.01, 0.0, 0.0, 0.002),
            strict=True,
        ):
            names.append(f"{joint}:{k}")
            values.append(v)
    return {
        "names": names,
        "values": values,
        "consistent_ls": False,
        "d2": 3.5,
        "used": "consistent",
    }


def arm_fit() -> ArmFit:
    """A hand-built fit of two joints: the shoulder judged, the elbow not determined."""
    doc = {
        "kind": "fricid-arm",
        "schema_version": 1,
        "joints": ["shoulder", "elbow"],
        "friction": {"shoulder": _friction(0.3, 0.05), "elbow": _friction(0, 0, False)},
        "base": {
            "names": ["shoulder:mz +0.1 elbow:m", "elbow:mz"],
            "values": [0.45, 0.1],
            "values_ls": [0.47, 0.09],
            "stderr": [0.01, None],
            "ci95": [[0.43, 0.47], [None, None]],
            "determined": [True, False],
        },
        "standard": _standard(),
        "noise": {"shoulder": 0.02, "elbow": None},
        "validation": {
            "shoulder": {
                "rmse": 0.022,
                "ratio": 1.1,
                "source": "second log",
                "level": "yes",
                "reasons": [],
            },
            "elbow": {
                "rmse": None,
                "ratio": None,
                "source": "second log",
                "level": "no",
                "reasons": ["the joint does not move in the log"],
            },
        },
        "provenance": {
            "source": "arm.parquet",
            "urdf": "arm.urdf",
            "estimator": "IDIM-WLS",
            "cutoff": 20.0,
            "samples": 900,
            "seconds": 1.5,
            "effective_samples": {"shoulder": 800.0, "elbow": 0.0},
        },
    }
    return ArmFit.from_dict(doc)


def test_a_row_per_joint_with_the_fits_own_verdicts():
    table = verdict_table(arm_fit())
    assert list(table["joint"]) == ["shoulder", "elbow"]
    assert list(table["Trust"]) == ["yes", "no"]
    assert table.loc[0, "held-out / noise"] == pytest.approx(1.1)
    assert math.isnan(table.loc[1, "held-out / noise"])
    assert table.loc[1, "why"] == "the joint does not move in the log"
    assert list(table["effective samples"]) == [800.0, 0.0]


def test_base_and_link_tables_render_the_recorded_numbers():
    fit = arm_fit()
    base = base_table(fit)
    assert list(base["least squares"]) == [0.47, 0.09]
    assert list(base["determined"]) == ["yes", "no"]
    assert math.isnan(base.loc[1, "95 % low"])
    links = link_table(fit)
    assert list(links["mass [kg]"]) == [2.0, 0.5]
    assert list(links["cz [m]"]) == pytest.approx([0.2, 0.2])  # first moment over the mass
    note = consistency_note(fit)
    assert "not physically consistent" in note and "3.5" in note


def test_document_draws_the_determined_joints_and_says_why_not_the_others(tmp_path):
    doc = arm_report(arm_fit())
    names = {t.name for t in doc.tables()}
    assert names == {"joints", "friction", "base_parameters", "links"}
    assert [f.name for f in doc.figures()] == ["friction_per_joint"]
    notes = [i.text for s in doc.sections for i in s.items if hasattr(i, "kind")]
    assert any(n.startswith("Not drawn: joint elbow") for n in notes)
    assert any("residual series" in n for n in notes)


def test_cli_reports_an_arm_file_without_data(tmp_path):
    path = arm_fit().save(tmp_path / "arm.json")
    out = tmp_path / "rep"
    res = runner.invoke(app, ["report", str(path), "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert {"report.html", "joints.csv", "friction_per_joint.png"} <= {
        p.name for p in out.iterdir()
    }
    assert list(pd.read_csv(out / "joints.csv")["Trust"]) == ["yes", "no"]
    res = runner.invoke(app, ["report", str(path), str(path), "--out", str(tmp_path / "b")])
    assert res.exit_code == 2 and "takes no data file" in res.output
    assert not (tmp_path / "b").exists()


@pytest.mark.slow  # a simulated log, a whole-arm fit and its report: about 20 s
def test_simulate_fit_report_end_to_end(tmp_path):
    log, fit, out = tmp_path / "log.parquet", tmp_path / "arm.json", tmp_path / "rep"
    res = runner.invoke(
        app,
        ["robot", "simulate", "--robot", "double_pendulum", "--duration", "6", "--out", str(log)],
    )
    assert res.exit_code == 0, res.output
    from fricid.robot.examples import example_urdf

    urdf, _ = example_urdf("double_pendulum")
    res = runner.invoke(app, ["robot", "fit", str(log), "--urdf", str(urdf), "-o", str(fit)])
    assert res.exit_code == 0, res.output
    res = runner.invoke(app, ["report", str(fit), "--out", str(out)])
    assert res.exit_code == 0, res.output
    joints = pd.read_csv(out / "joints.csv")
    arm = ArmFit.load(fit)
    assert list(joints["joint"]) == list(arm.joints)
    assert list(joints["Trust"]) == [arm.verdict(j) for j in arm.joints]
    assert len(pd.read_csv(out / "base_parameters.csv")) == len(arm.base["names"])
    assert "Whole-arm identification" in (out / "report.md").read_text()


def test_the_header_says_how_closed_loop_was_decided():
    """Whether the rows near the reversals were left out, and whether fricid decided it from
    the data or was told ("given: ..."), is part of what the numbers mean."""
    older = arm_report(arm_fit()).meta  # a file from before the decision was recorded
    assert older["closed loop"] == "not recorded"
    doc = arm_fit().to_dict()
    doc["provenance"] |= {"reversal_window": 1.0, "closed_loop": "detected: the residuals of x"}
    decided = arm_report(ArmFit.from_dict(doc)).meta
    assert decided["closed loop"] == "detected: the residuals of x"
    assert decided["rows near reversals left out [periods]"] == "1"
