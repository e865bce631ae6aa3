"""Exports say what a model's verdict is and refuse a ``no`` unless told
(``fricid export``, ``fricid robot export``, which also takes a whole-arm fit file), and a
whole-arm joint whose Stribeck rise the fit held at zero exports as the law it fitted."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

pytest.importorskip("pinocchio")

from fricid.cli import app
from fricid.cli.robot_fit import _pm
from fricid.fitted.arm import ArmFit
from fricid.identify.dynamic.arm._grade import MIN_EFFECTIVE, grade
from fricid.io import write_robot_log
from fricid.robot import RigidBodyModel, example_urdf

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "identify" / "dynamic"))
from _arm_truth import CV_LAWS, make_log

runner = CliRunner()


@pytest.fixture(scope="module")
def arm_file(tmp_path_factory):
    path, joints = example_urdf("double_pendulum")
    model = RigidBodyModel.from_urdf(path, joints)
    folder = tmp_path_factory.mktemp("arm")
    logs = [
        write_robot_log(
            make_log(model, CV_LAWS, duration=12.0, rate=250.0, seed=s, noise=0.05),
            folder / f"log{s}.csv",
        )
        for s in (3, 4)
    ]
    out = folder / "arm.json"
    fit = ["robot", "fit", str(logs[0]), "--urdf", path, "--friction", "coulomb_viscous_asym"]
    res = runner.invoke(app, [*fit, "--validate", str(logs[1]), "-o", str(out)])
    assert res.exit_code == 0, res.output
    return out


def _with_joint2_no(arm_file: Path, tmp_path: Path) -> Path:
    doc = json.loads(arm_file.read_text())
    doc["validation"]["joint2"].update(level="no", reasons=["the held-out error misses by 9x"])
    out = tmp_path / "arm_no.json"
    out.write_text(json.dumps(doc))
    return out


def test_a_whole_arm_fit_exports_every_joint_in_the_urdf_order(arm_file, tmp_path):
    levels = [ArmFit.load(arm_file).verdict(j) for j in ("joint1", "joint2")]
    assert "no" not in levels
    res = runner.invoke(app, ["robot", "export", str(arm_file), "--to", "c", "-o", str(tmp_path)])
    assert res.exit_code == 0, res.output
    header = (tmp_path / "fricid_friction.h").read_text()
    assert header.index("joint 0: joint1") < header.index("joint 1: joint2")
    for joint, level in zip(("joint1", "joint2"), levels, strict=True):  # the header says
        assert f"{joint} -> fricid_{joint}_friction (trust verdict: {level})" in header
    source = (tmp_path / "fricid_friction.c").read_text()
    for level in levels:  # each joint's comment gives its verdict
        assert f"trust verdict: {level}" in source
    assert source.count("the model file gives the reasons") == 2  # one line per joint
    assert "arm.json (joint2)" in source and "identified by IDIM-WLS (whole arm)" in source
    args = ["robot", "export", str(arm_file), "--to", "c", "-o", str(tmp_path / "c2")]
    res = runner.invoke(app, [*args, "--robot", "double_pendulum"])  # was ignored silently
    assert res.exit_code == 0, res.output
    assert "--robot applies to urdf and mjcf only; ignored for c" in " ".join(res.output.split())


def test_a_joint_whose_verdict_is_no_is_not_exported_unless_told(arm_file, tmp_path):
    arm = _with_joint2_no(arm_file, tmp_path)
    out = tmp_path / "c"
    res = runner.invoke(app, ["robot", "export", str(arm), "--to", "c", "-o", str(out)])
    assert res.exit_code != 0
    assert "joint joint2" in res.output and "--allow-untrusted" in res.output
    assert not out.exists() or not any(out.iterdir())  # nothing written
    res = runner.invoke(
        app, ["robot", "export", str(arm), "--to", "c", "-o", str(out), "--allow-untrusted"]
    )
    assert res.exit_code == 0, res.output
    assert "trust verdict: NO, exported anyway" in (out / "fricid_friction.c").read_text()


def test_every_refused_joint_is_named_and_an_unkept_number_is_explained(arm_file, tmp_path):
    """Joint 1 with a parameter the fit did not determine (no number kept) and joint 2 with a
    'no': one error names both; the flags say what they can and cannot do, and the advice is
    a family other than the one fitted."""
    doc = json.loads(_with_joint2_no(arm_file, tmp_path).read_text())
    doc["friction"]["joint1"]["parameters"]["beta_pos"].update(value=None, not_determined=True)
    arm = tmp_path / "arm_both.json"
    arm.write_text(json.dumps(doc))
    args = ["robot", "export", str(arm), "--to", "c", "-o", str(tmp_path / "c")]
    res = runner.invoke(app, [*args, "--allow-undetermined", "--allow-untrusted"])
    assert res.exit_code != 0
    text = " ".join(res.output.split())
    assert "joint joint1: not determined by the data: beta_pos" in text
    assert "keeps no number" in text and "even when allowed" in text
    assert "fit coulomb_viscous (one set for both directions) instead" in text
    res = runner.invoke(app, args)
    text = " ".join(res.output.split())
    assert res.exit_code != 0 and "2 joints refused" in text and "joint joint2" in text


def test_the_single_joint_export_refuses_a_no_too(arm_file, tmp_path):
    model = ArmFit.load(_with_joint2_no(arm_file, tmp_path)).joint_model("joint2")
    path = tmp_path / "joint2.json"
    model.save(path)
    res = runner.invoke(app, ["export", str(path), "--to", "urdf", "-o", str(tmp_path / "j.urdf")])
    assert res.exit_code != 0 and "trust verdict is 'no'" in res.output
    assert not (tmp_path / "j.urdf").exists()
    flags = ["--to", "urdf", "-o", str(tmp_path / "j.urdf"), "--allow-untrusted"]
    assert runner.invoke(app, ["export", str(path), *flags]).exit_code == 0
    assert "NO, exported anyway" in (tmp_path / "j.urdf").read_text()


def _record(value, lo=None, hi=None, note="", nd=False):
    return {"value": value, "unit": "", "stderr": None, "ci95": [lo, hi], "note": note,
            "not_determined": nd}  # fmt: skip


def test_a_rise_held_at_zero_exports_as_the_law_without_it():
    held = "not determined: the data show no Stribeck rise; its excess held at zero"
    params = {}
    for d, nd in (("_pos", False), ("_neg", True)):
        params |= {
            f"tau_c{d}": _record(0.4, 0.39, 0.41),
            f"tau_s{d}": _record(None, nd=True, note=held) if nd else _record(0.6, 0.55, 0.65),
            f"w_s{d}": _record(None, nd=True) if nd else _record(0.05, 0.04, 0.06),
            f"tau_v{d}": _record(0.2, 0.19, 0.21),
            f"delta{d}": _record(None, nd=True) if nd else _record(1.2, 1.0, 1.4),
        }
    params["tau_s_neg"]["held_at"] = 0.0
    fit = ArmFit(
        joints=("j",),
        friction={"j": {"family": "stribeck_asym", "parameters": params}},
        noise={"j": 0.01},
        validation={"j": {"rmse": 0.01, "ratio": 1.0, "level": "with caveats", "reasons": []}},
    )
    model = fit.joint_model("j")
    v = np.array([-1.0, -0.05, -0.001, 0.001, 0.05, 1.0])
    negative = -(0.4 + 0.2 * np.abs(v[:3]))  # Coulomb-viscous: no rise that way
    np.testing.assert_allclose(model.predict_point(v)[:3], negative, rtol=1e-12)
    assert model.predict_point(0.001) > 0.59  # the positive rise is kept
    assert model.validation["level"] == "with caveats"


def test_a_joint_on_too_few_independent_samples_gets_no_and_no_ratio():
    level, reasons = grade(6e13, [], [], "second log", True, effective=3.0)
    assert level == "no" and "only 3 independent samples" in reasons[0]
    assert not any("misses" in r for r in reasons)
    level, _ = grade(1.0, [], [], "second log", True, effective=MIN_EFFECTIVE)
    assert level == "yes"


def test_a_one_sided_interval_is_printed_with_its_ends():
    assert _pm(_record(0.05, 0.0, 0.06)) == "0.05 [0, 0.06]"
    assert _pm(_record(1.0, 0.9, 1.1)) == "1 +- 0.1"
    note = "not bounded by the data (its interval reaches the searched range's limit)"
    assert _pm(_record(4.0, 0.3, 4.0, note=note)) == "4 [0.3, 4] (not bounded)"


def test_the_single_joint_export_points_a_whole_arm_fit_to_robot_export(arm_file, tmp_path):
    res = runner.invoke(app, ["export", str(arm_file), "--to", "urdf", "-o", str(tmp_path / "x")])
    assert res.exit_code != 0 and "fricid robot export" in res.output
    res = runner.invoke(
        app, ["robot", "export", str(arm_file), str(arm_file), "--to", "c", "-o", str(tmp_path)]
    )
    assert res.exit_code != 0 and "is given twice" in res.output
    assert not (tmp_path / "fricid_friction.c").exists()


def test_a_cut_or_incomplete_arm_file_is_named_with_what_is_wrong(arm_file, tmp_path):
    bare, cut = tmp_path / "bare.json", tmp_path / "cut.json"
    bare.write_text('{"kind": "fricid-arm"}')
    cut.write_text(arm_file.read_text()[:300])
    for path, why in ((bare, "'schema_version' is missing"), (cut, "not valid JSON")):
        res = runner.invoke(app, ["robot", "export", str(path), "--to", "c", "-o", str(tmp_path)])
        assert res.exit_code != 0 and path.name in res.output and why in res.output
    assert "character" in res.output  # where in the line the cut file stops
    assert not (tmp_path / "fricid_friction.c").exists()


def test_a_whole_arm_fit_exports_as_the_robot_s_urdf_and_mjcf(arm_file, tmp_path):
    """`robot export --to urdf` rewrites the URDF with the identified inertials and each
    joint's <dynamics>; `--to mjcf` writes MuJoCo's model; both need the URDF and a file."""
    import xml.etree.ElementTree as ET

    path, _ = example_urdf("double_pendulum")
    out = tmp_path / "identified.urdf"
    args = ["robot", "export", str(arm_file), "--to", "urdf", "--urdf", str(path), "-o", str(out)]
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    root = ET.parse(out).getroot()
    dynamics = {j.get("name"): j.find("dynamics") for j in root.findall("joint")}
    assert dynamics["joint1"] is not None and float(dynamics["joint2"].get("friction")) > 0
    fit = ArmFit.load(arm_file)
    masses = [float(m.get("value")) for m in root.iter("mass")]
    assert any(np.isclose(m, v) for m in masses for v in fit.standard["values"][::10])
    xml = tmp_path / "arm.xml"
    res = runner.invoke(app, [*args[:4], "mjcf", "--robot", "double_pendulum", "-o", str(xml)])
    assert res.exit_code == 0, res.output
    assert "frictionloss" in xml.read_text()
    mujoco = pytest.importorskip("mujoco")
    assert mujoco.MjModel.from_xml_path(str(xml)).njnt == 2
    res = runner.invoke(app, [*args[:5], "-o", str(tmp_path / "x.urdf")])
    assert res.exit_code == 2 and "give --urdf or --robot" in res.output
    assert not (tmp_path / "x.urdf").exists()


def test_urdf_and_mjcf_say_each_joint_s_verdict(arm_file, tmp_path):
    """Each joint's trust verdict is in the URDF's <dynamics> comment and the MJCF's first
    comment, as in the C and YAML exports; a 'no' exported when told says so (both files
    had carried friction fricid rejected without a mark)."""
    arm = _with_joint2_no(arm_file, tmp_path)
    path, _ = example_urdf("double_pendulum")
    level = ArmFit.load(arm_file).verdict("joint1")
    base = ["robot", "export", str(arm), "--allow-untrusted", "--urdf", str(path), "--to"]
    out = tmp_path / "identified.urdf"
    res = runner.invoke(app, [*base, "urdf", "-o", str(out)])
    assert res.exit_code == 0, res.output
    text = out.read_text()
    # the inertials are what reproduces the base parameters, not all identified
    assert "what the data do not determine keeps the URDF's values" in " ".join(text.split())
    joint1, joint2 = (ln for ln in text.splitlines() if "trust verdict: " in ln)
    # joint1's symmetric projection of its two-sided model: graded as the numbers it holds
    assert f"the model itself: {level}" in joint1 or f"trust verdict: {level}" in joint1
    assert "trust verdict: NO, exported anyway" in joint2
    xml = tmp_path / "arm.xml"
    res = runner.invoke(app, [*base, "mjcf", "-o", str(xml)])
    assert res.exit_code == 0, res.output
    text = xml.read_text()
    assert f"joint joint1: trust verdict: {level}" in text
    assert "joint joint2: trust verdict: NO, exported anyway" in text
    assert "what the data do not determine keeps the URDF's values" in " ".join(text.split())
