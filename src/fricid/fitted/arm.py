"""A whole arm's identified dynamics: :class:`ArmFit` and its JSON file.

One record per robot: each joint's friction (family, parameters with 95 % intervals), the
base inertial parameters with names and intervals, the physically consistent standard
parameters, the noise per joint, the held-out error over the noise and the verdict per joint,
and the provenance (log, URDF, filter, estimator). The file is JSON with ``"kind":
"fricid-arm"`` and :data:`ARM_SCHEMA_VERSION`, written atomically and read strictly
(:func:`fricid.io._jsonfile.read_json`). Each joint's friction is also a
:class:`~fricid.fitted.FittedModel` (:meth:`ArmFit.joint_model`), so what works on one
joint's model (predict, export) works on it.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ConfigError, DataError
from ..io._jsonfile import read_json
from ..metrics import verdict
from ._file import _clean
from ._parameter import OptimizerRecord, Parameter

__all__ = ["ARM_KIND", "ARM_SCHEMA_VERSION", "LOAD_FAMILIES", "ArmFit"]

#: The file's kind and version.
ARM_KIND = "fricid-arm"
ARM_SCHEMA_VERSION = 1

_NAN = float("nan")


def _nan(value: Any) -> float:
    return _NAN if value is None else float(value)


#: The whole-arm load families and the model (BAS-RBFNN paper eq. 3, ``msk``) they are: its
#: parameter names and units, with ``f_s = f_c`` and ``f_sk = f_ck``.
LOAD_FAMILIES = {"coulomb_viscous_load": "msk", "coulomb_viscous_load_asym": "msk_asym"}


def _as_msk(params: dict[str, Parameter]) -> dict[str, Parameter]:
    """A load family's parameters as ``msk``'s: ``f_s = f_c`` and ``f_sk = f_ck`` (no Stribeck
    rise), so ``v_s`` and ``xi`` do not matter; they are fixed at 1."""
    out: dict[str, Parameter] = {}
    for d in ("_pos", "_neg") if "f_c_pos" in params else ("",):
        for name, like in (("f_c", "f_c"), ("f_s", "f_c"), ("f_ck", "f_ck"), ("f_sk", "f_ck")):
            out[f"{name}{d}"] = replace(params[f"{like}{d}"], name=f"{name}{d}")
        for name, unit in (("v_s", "rad/s"), ("xi", "1")):
            note = "no Stribeck rise (f_s = f_c): does not matter"
            out[f"{name}{d}"] = Parameter(f"{name}{d}", 1.0, unit=unit, fixed=True, note=note)
        out[f"beta{d}"] = params[f"beta{d}"]
    return out


def _without_rise(params: dict[str, Parameter], entry: dict[str, Any]) -> dict[str, Parameter]:
    """A Stribeck family's directions whose excess the fit held at zero (its record's
    ``held_at``: the fitted rows showed no rise, or did not see it) as the law the fit used:
    ``tau_s = tau_c``, so that ``w_s`` and ``delta`` do not matter (fixed at 1)."""
    out = dict(params)
    for d in ("_pos", "_neg", ""):
        rec = entry["parameters"].get(f"tau_s{d}", {})
        if rec.get("held_at") != 0.0:
            continue
        note = "no Stribeck rise fitted (tau_s = tau_c): does not matter"
        out[f"tau_s{d}"] = replace(params[f"tau_c{d}"], name=f"tau_s{d}", note=rec["note"])
        for name, unit in (("w_s", "rad/s"), ("delta", "1")):
            out[f"{name}{d}"] = Parameter(f"{name}{d}", 1.0, unit=unit, fixed=True, note=note)
    return out


def _simpler(family: str) -> str:
    """What to do when a joint's ``family`` leaves parameters undetermined: a family with
    fewer parameters where there is one, else more informative data."""
    more = "or record the joint moving more, slower and both ways"
    if family == "lugre":
        return (
            "fit stribeck (LuGre's steady state) instead, or record the joint reversing "
            "slowly, many times, with a finer encoder"
        )
    if family.startswith("stribeck"):
        return f"fit coulomb_viscous{'_asym' if family.endswith('_asym') else ''} instead, {more}"
    if family.endswith("_asym"):
        return f"fit {family[: -len('_asym')]} (one set for both directions) instead, {more}"
    if family.startswith("coulomb_viscous_load"):
        return f"fit coulomb_viscous instead, {more}"
    return more[3:]


@dataclass
class ArmFit:
    """A whole arm's identification (module notes).

    Attributes
    ----------
    joints : tuple of str
        The identified joints, in the model's order.
    friction : dict
        joint -> ``{"family": str, "parameters": {name: record}}``; a record holds ``value``,
        ``unit``, ``stderr``, ``ci95`` (two ends) and ``not_determined``.
    base : dict
        ``names``, ``values``, ``stderr``, ``ci95`` (a pair per parameter), ``determined``.
    standard : dict
        ``names``, ``values`` (10 per joint, physical), ``consistent_ls`` (the least-squares
        base parameters were already physical), ``d2`` (their Mahalanobis distance from the
        consistent ones), ``used`` (``"least squares"`` or ``"consistent"``).
    noise : dict
        joint -> the torque noise [N m] after the filter.
    validation : dict
        joint -> ``{"rmse", "ratio", "source", "level", "reasons"}``.
    provenance : dict
        Log, URDF, filter cut-off and its bounds, decimation, estimator, samples, effective
        samples, clusters, seconds, fricid version.
    """

    joints: tuple[str, ...]
    friction: dict[str, dict[str, Any]] = field(default_factory=dict)
    base: dict[str, Any] = field(default_factory=dict)
    standard: dict[str, Any] = field(default_factory=dict)
    noise: dict[str, float] = field(default_factory=dict)
    validation: dict[str, dict[str, Any]] = field(default_factory=dict)
    provenance: dict[str, Any] = field(default_factory=dict)

    def verdict(self, joint: str) -> str:
        """The joint's verdict level (``"yes"``, ``"with caveats"``, ``"no"``)."""
        return str(self.validation.get(joint, {}).get("level", "no"))

    def parameter(self, joint: str, name: str) -> Parameter:
        """One friction parameter's record as a :class:`Parameter`."""
        rec = self.friction[joint]["parameters"][name]
        ci = rec.get("ci95") or (None, None)
        return Parameter(
            name,
            _nan(rec.get("value")),
            unit=str(rec.get("unit", "")),
            stderr=_nan(rec.get("stderr")),
            ci95=(_nan(ci[0]), _nan(ci[1])),
            ci95_halfwidth=(_nan(ci[1]) - _nan(ci[0])) / 2,
            note=str(rec.get("note", "")),
            not_determined=bool(rec.get("not_determined", False)),
        )

    def joint_model(self, joint: str):
        """The joint's friction as a :class:`~fricid.fitted.FittedModel` of its family.

        Raises
        ------
        ConfigError
            A parameter is not determined (no number to predict with).
        """
        from . import FittedModel

        if joint not in self.friction:
            raise ConfigError(f"no joint {joint!r} in this fit; joints: {', '.join(self.joints)}")
        entry = self.friction[joint]
        params = _without_rise({n: self.parameter(joint, n) for n in entry["parameters"]}, entry)
        for n, p in params.items():  # a joint without load: the load term never acts
            if n.startswith("f_ck") and "carries no load" in p.note:
                params[n] = replace(p, value=0.0, fixed=True, not_determined=False)
        missing = [n for n, p in params.items() if p.not_determined or not np.isfinite(p.value)]
        if missing:
            raise ConfigError(
                f"joint {joint}: not determined by the data: {', '.join(missing)}; the arm fit "
                "keeps no number for such a parameter, so there is none to predict or export "
                f"with, even when allowed ({_simpler(entry['family'])})"
            )
        check = self.validation.get(joint, {})
        velocity = list(entry.get("velocity_range", [-1.0, 1.0]))
        family, ranges = entry["family"], {"velocity": velocity}
        if family in LOAD_FAMILIES:  # eq. 3's msk without its Stribeck rise
            family, params = LOAD_FAMILIES[family], _as_msk(params)
            ranges["load"] = list(entry.get("load_range", [0.0, 0.0]))
        estimator = str(self.provenance.get("estimator") or "IDIM-WLS")
        return FittedModel(
            model=family,
            parameters=params,
            ci_method="cluster-robust",
            optimizer=OptimizerRecord(method=f"{estimator} (whole arm)"),
            operating_range=ranges,
            provenance={
                "source": self.provenance.get("source"),
                "joint": joint,
                "arm_fit": True,
                "estimator": self.provenance.get("estimator"),
            },
            validation={
                "scheme": f"whole-arm held out: {check.get('source', '')}",
                "rmse": check.get("rmse"),
                "scatter": self.noise.get(joint),
                "ratio": check.get("ratio"),
                "verdict": verdict(_nan(check.get("ratio"))),
                # the joint's trust level, every reason counted (not the ratio's alone)
                "level": str(check.get("level", "no")),
                "reasons": [str(r) for r in check.get("reasons", [])],
            },
        )

    # -- file ----------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """The file's JSON document."""
        from .. import __version__

        d = {f.name: getattr(self, f.name) for f in fields(self)}
        d["joints"] = list(self.joints)
        head = {"kind": ARM_KIND, "schema_version": ARM_SCHEMA_VERSION}
        return _clean({**head, "fricid_version": __version__, **d})

    @classmethod
    def from_dict(cls, d: dict[str, Any], source: str | None = None) -> ArmFit:
        """The fit a parsed file describes.

        Raises
        ------
        DataError
            Not a whole-arm fit file, a newer version, or a field missing or of the wrong type.
        """
        if not isinstance(d, dict) or d.get("kind") != ARM_KIND:
            raise DataError(f"not a fricid whole-arm fit (no kind '{ARM_KIND}')", file=source)
        version = d.get("schema_version")
        if version is None:
            raise DataError(
                "field 'schema_version' is missing: fricid robot fit writes it, so the file "
                "is incomplete or not fricid's",
                file=source,
            )
        if not isinstance(version, int) or not 1 <= version <= ARM_SCHEMA_VERSION:
            raise DataError(
                f"whole-arm fit schema version {version!r} is not one this fricid reads "
                f"(1 to {ARM_SCHEMA_VERSION})",
                file=source,
            )
        joints = d.get("joints")
        if not isinstance(joints, list) or not all(isinstance(j, str) for j in joints):
            raise DataError("field 'joints' must be a list of names", file=source)
        kw: dict[str, Any] = {}
        for f in fields(cls):
            if f.name == "joints":
                continue
            value = d.get(f.name, {})
            if not isinstance(value, dict):
                raise DataError(f"field '{f.name}' must be an object", file=source)
            kw[f.name] = value
        for j in joints:
            entry = kw["friction"].get(j)
            if not isinstance(entry, dict) or not isinstance(entry.get("parameters"), dict):
                raise DataError(f"field 'friction/{j}' must hold 'parameters'", file=source)
        return cls(joints=tuple(joints), **kw)

    def save(self, path: str | PathLike[str]) -> Path:
        """Write the fit as JSON, atomically."""
        from ..io._jsonfile import write_json

        return write_json(path, self.to_dict())

    @classmethod
    def load(cls, path: str | PathLike[str]) -> ArmFit:
        """Read a whole-arm fit file strictly (:func:`fricid.io._jsonfile.read_json`)."""
        return cls.from_dict(read_json(path, what="whole-arm fit"), source=str(path))
