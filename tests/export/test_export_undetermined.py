"""A trajectory model with a parameter the data do not determine is not exported unless the
user allows it, and then the exported file names it."""

from __future__ import annotations

import dataclasses

import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.export import ExportError, refuse_undetermined, undetermined_parameters
from fricid.fitted import FittedModel

runner = CliRunner()
#: The MuJoCo timestep check is tested in test_mujoco_step.py.
NO_CHECK = ("--no-timestep-check",)
LUGRE = dict(sigma_0=1e3, sigma_1=0.5, sigma_2=0.1, tau_c=0.3, tau_s=0.5, w_s=0.05, delta=2.0)
NOTE = "not identified: the 95 % interval spans the whole search range [0.001, 1000]"


def trajectory_model(undetermined: tuple[str, ...] = ("sigma_1",), **prov) -> FittedModel:
    """A LuGre model as a trajectory fit records it, ``undetermined`` marked so."""
    fitted = FittedModel.from_values(
        "lugre",
        LUGRE,
        operating_range={"velocity": [-2.0, 2.0]},
        provenance={"trajectory": {"route": "filtered"}, **prov},
    )
    for name in undetermined:
        fitted.parameters[name] = dataclasses.replace(
            fitted.parameters[name], note=NOTE, not_determined=True
        )
    return fitted


def test_only_a_trajectory_models_undetermined_parameters_count():
    assert undetermined_parameters(trajectory_model(("sigma_1", "sigma_0"))) == [
        "sigma_0",
        "sigma_1",
    ]
    assert undetermined_parameters(trajectory_model(())) == []
    static = trajectory_model()
    static.provenance = {}  # not from a trajectory: the static path's own rules apply
    assert undetermined_parameters(static) == []
    with pytest.raises(ExportError, match=r"does not determine sigma_1 of the 'lugre'"):
        refuse_undetermined(trajectory_model(), allow=False)
    refuse_undetermined(trajectory_model(), allow=True)


def test_cli_refuses_then_names_an_undetermined_parameter(tmp_path):
    path = tmp_path / "lugre.json"
    trajectory_model().save(path)
    assert FittedModel.load(path).parameters["sigma_1"].not_determined  # kept in the file
    out = tmp_path / "lugre.mjcf"
    res = runner.invoke(app, ["export", str(path), "--to", "mjcf", "-o", str(out)])
    assert res.exit_code == 2 and not out.exists()
    assert "--allow-undetermined" in " ".join(res.output.split())
    res = runner.invoke(
        app,
        ["export", str(path), "--to", "mjcf", "-o", str(out), "--allow-undetermined", *NO_CHECK],
    )
    assert res.exit_code == 0, res.output
    text = out.read_text()
    assert "NOT DETERMINED by the trajectory, exported as identified: sigma_1" in text
    determined = tmp_path / "determined.json"
    trajectory_model(()).save(determined)
    res = runner.invoke(
        app, ["export", str(determined), "--to", "mjcf", "-o", str(out), "--no-timestep-check"]
    )
    assert res.exit_code == 0 and "NOT DETERMINED" not in out.read_text()


def test_the_projection_says_which_undetermined_parameters_it_rests_on(tmp_path):
    """A Coulomb-viscous projection (yaml, urdf, the MJCF line without dcmotor) is a function
    of the steady state: an undetermined tau_s moves it, an undetermined sigma_1 does not."""
    fitted = trajectory_model(("tau_s", "sigma_1"))
    fitted.parameters["tau_s"] = dataclasses.replace(fitted.parameters["tau_s"], bounds=(0.0, 2.0))
    path = tmp_path / "lugre.json"
    fitted.save(path)
    for target, name in (("yaml", "f.yaml"), ("urdf", "f.urdf"), ("mjcf", "f.xml")):
        out = tmp_path / name
        args = ["export", str(path), "--to", target, "-o", str(out), "--allow-undetermined"]
        res = runner.invoke(app, [*args, *(NO_CHECK if target == "mjcf" else ())])
        assert res.exit_code == 0, res.output
        text = " ".join(out.read_text().split()).replace("# ", "")
        assert "rests on tau_s, which the trajectory does not determine" in text, target
        assert "search range 0 to 2 N m" in text
        assert "rests on sigma_1" not in text
    determined = trajectory_model(("sigma_1",))
    determined.save(path)
    out = tmp_path / "g.yaml"
    res = runner.invoke(
        app, ["export", str(path), "--to", "yaml", "-o", str(out), "--allow-undetermined"]
    )
    assert res.exit_code == 0 and "rests on" not in out.read_text()


def test_the_span_is_the_projection_at_the_ends_of_the_search_range():
    from fricid.export import project

    fitted = trajectory_model(("tau_s",))
    fitted.parameters["tau_s"] = dataclasses.replace(fitted.parameters["tau_s"], bounds=(0.0, 2.0))
    (line,) = project(fitted, False).rests_on
    pairs = []
    for tau_s in (0.0, 0.5, 2.0):
        other = FittedModel.from_values(
            "lugre", {**LUGRE, "tau_s": tau_s}, operating_range={"velocity": [-2.0, 2.0]}
        )
        proj = project(other, False)
        pairs.append((proj.coulomb["both"], proj.viscous["both"]))
    fc, b = zip(*pairs, strict=True)
    assert f"F_c spans {min(fc):.4g} to {max(fc):.4g} N m" in line
    assert f"b {min(b):.4g} to {max(b):.4g} N m s/rad" in line
    assert max(fc) - min(fc) > 0.1  # the Stribeck level moves the Coulomb level


def test_a_projection_is_refused_only_for_what_its_numbers_depend_on(tmp_path):
    """yaml and urdf hold the steady-state Coulomb-viscous projection, which a LuGre model's
    sigma_1 does not move: exported without the flag, the comment saying sigma_1 is not in
    the file; an undetermined tau_s (which moves it) is refused, named alone; MJCF (the
    dcmotor holds sigma_0 and sigma_1) still refuses sigma_1."""
    path = tmp_path / "lugre.json"
    trajectory_model(("sigma_1",)).save(path)
    for target in ("yaml", "urdf"):
        out = tmp_path / f"f.{target}"
        res = runner.invoke(app, ["export", str(path), "--to", target, "-o", str(out)])
        assert res.exit_code == 0, res.output
        text = " ".join(out.read_text().split()).replace("# ", "")
        assert "not in this file (its numbers do not depend on it): sigma_1" in text, target
        assert "exported as identified: sigma_1" not in text
    res = runner.invoke(app, ["export", str(path), "--to", "mjcf", *NO_CHECK])
    assert res.exit_code == 2 and "does not determine sigma_1" in " ".join(res.output.split())
    fitted = trajectory_model(("sigma_0", "tau_s"))
    fitted.parameters["tau_s"] = dataclasses.replace(fitted.parameters["tau_s"], bounds=(0.0, 2.0))
    fitted.save(path)
    res = runner.invoke(app, ["export", str(path), "--to", "yaml"])
    said = " ".join(res.output.split())
    assert res.exit_code == 2 and "does not determine tau_s of the 'lugre'" in said
    out = tmp_path / "g.yaml"
    args = ["export", str(path), "--to", "yaml", "-o", str(out), "--allow-undetermined"]
    assert runner.invoke(app, args).exit_code == 0
    text = " ".join(out.read_text().split()).replace("# ", "")
    assert "exported as identified: tau_s" in text and "identified: sigma_0" not in text
    assert "not in this file (its numbers do not depend on it): sigma_0" in text


def test_a_static_mjcf_of_another_family_refuses_what_its_projection_reads(tmp_path):
    fitted = FittedModel.from_values(
        "stribeck",
        {"tau_c": 0.3, "tau_s": 0.5, "w_s": 0.05, "tau_v": 0.1, "delta": 2.0},
        operating_range={"velocity": [-2.0, 2.0]},
        provenance={"trajectory": {"route": "filtered"}},
    )
    fitted.parameters["tau_s"] = dataclasses.replace(
        fitted.parameters["tau_s"], note=NOTE, not_determined=True, bounds=(0.0, 2.0)
    )
    path = fitted.save(tmp_path / "s.json")
    res = runner.invoke(app, ["export", str(path), "--to", "mjcf", *NO_CHECK])
    assert res.exit_code == 2 and "does not determine tau_s" in " ".join(res.output.split())


def test_robot_export_refuses_only_what_its_target_holds(tmp_path):
    """fricid robot export refused any undetermined parameter, also for ros2_control and
    URDF, which hold each joint's Coulomb-viscous projection (never a LuGre model's sigma_1);
    C holds the full model and still refuses it."""
    path = tmp_path / "elbow.json"
    trajectory_model().save(path)
    out = tmp_path / "arm.yaml"
    res = runner.invoke(app, ["robot", "export", f"elbow={path}", "--to", "yaml", "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert "not in this file" in " ".join(out.read_text().split())
    res = runner.invoke(
        app, ["robot", "export", f"elbow={path}", "--to", "c", "-o", str(tmp_path / "c")]
    )
    assert res.exit_code != 0 and "--allow-undetermined" in " ".join(res.output.split())
