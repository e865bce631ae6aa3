"""All joints of a robot at once: one ros2_control YAML, one C header and source with a
function per joint and a dispatcher (fricid.export.robot), and ``fricid robot export``."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from _c_harness import compile_c, needs_cc, points, relative_error
from fricid.cli import app
from fricid.export import ExportError, Smoothing, ros2_yaml_text, smooth_predict
from fricid.export.robot import (
    export_robot_c,
    joint_identifiers,
    robot_c_code,
    robot_ros2_yaml_text,
)
from fricid.fitted import FittedModel, OptimizerRecord

RANGE = {"velocity": [-1.0, 1.0], "load": [-0.5, 0.5], "temperature": [5.0, 45.0]}

#: Four joints of different families (one per direction, one with temperature), so their
#: generated code declares the same static names (model, f_c, ...) that must not collide.
MODELS = {
    "shoulder_pan": (
        "stribeck",
        {"tau_c": 0.15, "tau_s": 0.2, "w_s": 0.05, "tau_v": 0.02, "delta": 1.0},
    ),
    "shoulder_lift": (
        "coulomb_viscous_asym",
        {"f_c_pos": 0.3, "beta_pos": 0.11, "f_c_neg": 0.21, "beta_neg": 0.17},
    ),
    "elbow": ("coulomb_viscous", {"f_c": 0.25, "beta": 0.09}),
    "wrist-1": (
        "vlt",
        {
            "f_c": 0.05,
            "f_ctl": 0.6,
            "f_stl": 0.3,
            "f_v0": 0.2,
            "f_vT": -0.002,
            "v_tl0": 0.035,
            "v_v0": 0.4,
            "v_vT": 0.01,
        },
    ),
}


def _models() -> dict[str, FittedModel]:
    return {
        joint: FittedModel.from_values(
            name, params, operating_range=RANGE, optimizer=OptimizerRecord(method="test", seed=0)
        )
        for joint, (name, params) in MODELS.items()
    }


def _harness(robot: str, n: int) -> str:
    """A main reading ``joint v l T`` lines and printing the dispatcher's friction."""
    return (
        "#include <stdio.h>\n"
        f'#include "{robot}_friction.h"\n'
        "int main(void)\n{\n    int j;\n    double v, l, t;\n"
        '    while (scanf("%d %lf %lf %lf", &j, &v, &l, &t) == 4)\n'
        f'        printf("%.17g\\n", {robot}_friction(j, v, l, t));\n'
        f'    printf("%d\\n", {robot.upper()}_N_JOINTS);\n'
        "    return 0;\n}\n"
    )


@needs_cc
@pytest.mark.parametrize("smoothing", [Smoothing(), Smoothing("linear", 0.02)], ids=str)
def test_robot_c_matches_predict_for_every_joint(tmp_path, smoothing):
    models = _models()
    paths = export_robot_c(models, tmp_path, smoothing, robot="arm")
    assert [p.name for p in paths] == ["arm_friction.h", "arm_friction.c"]
    (tmp_path / "main.c").write_text(_harness("arm", len(models)))
    exe = compile_c(tmp_path, ("main.c", "arm_friction.c"), "robot")
    X = points(400)
    rows = []
    for j in range(len(models)):
        rows.extend(f"{j} {v!r} {load!r} {t!r}" for v, load, t in X.tolist())
    rows.append(f"{len(models)} 0.5 0.0 25.0")  # an index out of range: no feed-forward
    run = subprocess.run(
        [str(exe)], input="\n".join(rows), capture_output=True, text=True, check=True
    )
    out = np.array([float(x) for x in run.stdout.split()])
    assert out[-1] == len(models) and out[-2] == 0.0
    got = out[:-2].reshape(len(models), -1)
    for j, fitted in enumerate(models.values()):
        want = smooth_predict(fitted, X, smoothing)
        scale = None
        if smoothing.kind == "linear":
            scale = np.where(np.abs(X[:, 0]) < smoothing.zone, np.abs(want).max(), 0.0)
        assert relative_error(got[j], want, scale) <= 1e-12, list(models)[j]
    header = paths[0].read_text()
    assert "#define ARM_JOINT_WRIST_1 3" in header
    assert "double arm_shoulder_pan_friction(double velocity" in header


def test_robot_c_names_are_checked():
    models = _models()
    with pytest.raises(ExportError, match="same C name"):
        joint_identifiers(["wrist-1", "wrist_1"])
    with pytest.raises(ExportError, match="not a C identifier"):
        robot_c_code(models, robot="my robot")
    with pytest.raises(ExportError, match="no joint"):
        robot_c_code({})
    assert joint_identifiers(["1st", "a.b"]) == ["j1st", "a_b"]


def test_robot_yaml_has_a_block_per_joint_equal_to_the_single_joint_export():
    models = _models()
    text = robot_ros2_yaml_text(models, node="arm_ff", sources={"elbow": "elbow.json"})
    doc = yaml.safe_load(text)["arm_ff"]["ros__parameters"]
    assert doc["joints"] == list(models)
    for joint, fitted in models.items():
        single = yaml.safe_load(ros2_yaml_text(fitted, joint, node="arm_ff"))
        assert doc[joint] == single["arm_ff"]["ros__parameters"][joint]
    assert "# joint elbow:" in text and "from elbow.json" in text


def test_robot_yaml_refusal_names_the_joint():
    models = _models()
    two = {"elbow": models["elbow"], "wrist-1": models["wrist-1"]}
    with pytest.raises(ExportError, match=r"joint wrist-1: .*cannot represent"):
        robot_ros2_yaml_text(two, max_loss=0.01)


runner = CliRunner()


@needs_cc
def test_cli_robot_export_from_a_folder_and_from_pairs(tmp_path):
    models = _models()
    folder = tmp_path / "models"
    folder.mkdir()
    for joint, fitted in models.items():
        fitted.save(folder / f"{joint}.json")
    out = tmp_path / "c"
    res = runner.invoke(
        app, ["robot", "export", str(folder), "--to", "c", "--robot-name", "arm", "-o", str(out)]
    )
    assert res.exit_code == 0, res.output
    header = (out / "arm_friction.h").read_text()
    # a folder's models in the order of their file names
    assert [line.split()[1] for line in header.splitlines() if "_JOINT_" in line] == [
        "ARM_JOINT_ELBOW",
        "ARM_JOINT_SHOULDER_LIFT",
        "ARM_JOINT_SHOULDER_PAN",
        "ARM_JOINT_WRIST_1",
    ]
    yaml_out = tmp_path / "ff.yaml"
    pairs = [f"{j}={folder / (j + '.json')}" for j in ("shoulder_pan", "elbow")]
    res = runner.invoke(
        app, ["robot", "export", *pairs, "--to", "ros2_control", "-o", str(yaml_out)]
    )
    assert res.exit_code == 0, res.output
    doc = yaml.safe_load(yaml_out.read_text())
    assert doc["friction_compensation"]["ros__parameters"]["joints"] == ["shoulder_pan", "elbow"]
    # --to yaml (the single-joint export's name) is the same, here to stdout
    res = runner.invoke(app, ["robot", "export", *pairs, "--to", "yaml"])
    assert res.exit_code == 0 and res.stdout == yaml_out.read_text()
    strict = ["--to", "ros2_control", "--max-loss", "0.01", "-o", str(tmp_path / "x.yaml")]
    res = runner.invoke(app, ["robot", "export", str(folder), *strict])
    # the first joint beyond the tolerance is named, on one line, and nothing is written
    assert res.exit_code == 2 and "joint shoulder_pan: " in res.output, res.output
    assert "Traceback" not in res.output
    assert not (tmp_path / "x.yaml").exists()


def _rbf(inputs) -> FittedModel:
    """A small RBF network trained on the virtual joint's paper-1 law."""
    from fricid.identify.learned.rbf import fit_rbf
    from fricid.samples import FrictionSamples
    from fricid.sim import LoadTemperatureLaw

    rng = np.random.default_rng(1)
    v = 10.0 ** rng.uniform(-3, 0, 300) * rng.choice([-1.0, 1.0], 300)
    load, temp = rng.uniform(0.15, 0.21, 300), rng.uniform(5, 45, 300)
    s = FrictionSamples(
        velocity=v, load=load, temperature=temp, friction=LoadTemperatureLaw()(v, load, temp)
    )
    return fit_rbf(s, inputs, n_centers=12, random_state=0)


@pytest.mark.slow  # 2.7 s measured under load (two RBF fits and a compile)
@needs_cc
def test_robot_c_two_rbf_joints_share_one_source(tmp_path):
    """Two RBF networks (the same array and helper names in their generated code) and an
    analytic joint compile into one translation unit and match predict."""
    import warnings

    from _c_harness import sum_scale

    models = {"a": _rbf(("velocity", "load", "temperature")), "b": _rbf(("velocity",))}
    models["c"] = _models()["elbow"]
    export_robot_c(models, tmp_path, robot="r")
    (tmp_path / "main.c").write_text(_harness("r", 3))
    exe = compile_c(tmp_path, ("main.c", "r_friction.c"), "rbf")
    X = points(300)
    rows = [f"{j} {v!r} {load!r} {t!r}" for j in range(3) for v, load, t in X.tolist()]
    run = subprocess.run([str(exe)], input="\n".join(rows), capture_output=True, text=True)
    got = np.array([float(x) for x in run.stdout.split()])[:-1].reshape(3, -1)
    for j, fitted in enumerate(models.values()):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the points go beyond the identified range
            want = smooth_predict(fitted, X, Smoothing())
        scale = sum_scale(fitted, X) if fitted.kind == "rbf" else None
        assert relative_error(got[j], want, scale) <= 1e-12
