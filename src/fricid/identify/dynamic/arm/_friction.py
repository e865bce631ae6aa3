"""Each joint's friction as columns of the whole-arm regressor, per direction of motion.

A joint's friction torque adds to the rigid-body torque, ``tau = Y_b beta + F_j(dq_j)``, and
every family here is linear in all but the Stribeck shape (BAS-RBFNN paper eq. 1 and 2;
RWSAVSBAS paper eq. 7), written per direction ``d`` (``+`` for ``dq >= 0``, ``-`` below, as
:class:`fricid.models._asymmetric.Asymmetric` writes it: the negative set holds magnitudes):

* ``coulomb_viscous``: ``f_c sign(v) + beta v``;
* ``coulomb_viscous_asym``: ``s_d f_c,d + beta_d v`` on direction ``d``'s samples
  (``s_+ = 1``, ``s_- = -1``);
* ``coulomb_viscous_load`` (``_asym``): ``s_d (f_c,d + f_ck,d |tau_l|) + beta_d v``, the joint-load
  model of BAS-RBFNN paper eq. 3 without its Stribeck rise (``F_s = F_c``, ``F_sk = F_ck``),
  linear in all three; ``tau_l`` the joint's load torque (:mod:`._load`);
* ``stribeck_asym``: ``s_d [tau_c,d + (tau_s,d - tau_c,d) e_d] + tau_v,d v`` with
  ``e_d = exp(-(|v| / w_s,d)^delta_d)``, linear in ``(tau_c, tau_s - tau_c, tau_v)`` once
  ``(w_s, delta)`` are fixed (the separable structure that
  :mod:`fricid.identify.static.varpro` uses for one joint); ``stribeck`` is the same with one
  set for both directions.

:class:`JointFriction` gives the linear columns for given shapes, the Jacobian columns of the
shapes (for the intervals), and maps the internal linear parameters back to the family's.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ....errors import ConfigError

__all__ = ["FAMILIES", "JointFriction", "excess_cap", "friction_for", "split_direction"]

#: The families a joint's friction may take in a whole-arm fit.
FAMILIES = (
    "coulomb_viscous",
    "coulomb_viscous_asym",
    "coulomb_viscous_load",
    "coulomb_viscous_load_asym",
    "stribeck",
    "stribeck_asym",
)

#: A joint whose load never exceeds this [N m] carries none: its load coefficient has no
#: column and is not determined (on the Panda's vertical first axis gravity's torque is 1e-14
#: N m of rounding, which as a column gave a coefficient of 1e11).
NO_LOAD = 1e-9


#: Start and search box of the Stribeck velocity [rad/s] and exponent.
W_S_START, W_S_BOX = 0.05, (1e-3, 1.0)
DELTA_START, DELTA_BOX = 1.0, (0.3, 4.0)


def _directions(family: str) -> tuple[str, ...]:
    return ("_pos", "_neg") if family.endswith("_asym") else ("",)


def _mask(v: np.ndarray, suffix: str) -> tuple[np.ndarray, np.ndarray]:
    """(indicator, sign) of a direction's samples."""
    if suffix == "_pos":
        ind = (v > 0).astype(float)
        return ind, ind
    if suffix == "_neg":
        ind = (v < 0).astype(float)
        return ind, -ind
    return (v != 0).astype(float), np.sign(v)


def stribeck_shape(v: np.ndarray, w_s: float, delta: float) -> np.ndarray:
    """``exp(-(|v| / w_s)^delta)`` (module notes)."""
    return np.exp(-((np.abs(v) / w_s) ** delta))


@dataclass
class JointFriction:
    """One joint's friction family and its current Stribeck shapes (module notes)."""

    family: str
    shapes: dict[str, tuple[float, float]] = field(default_factory=dict)
    #: a load family's joint that carries no load (:data:`NO_LOAD`): no load column
    unloaded: bool = False
    #: the largest Stribeck excess ``tau_s - tau_c`` the log allows [N m] (:func:`excess_cap`)
    excess_max: float = np.inf
    #: direction -> the share of its Stribeck column on the fitted rows that leaks there
    #: through the filters from rows left out (``_solve.unseen_rises``); above
    #: ``_solve.LEAK_MAX`` the rise is not seen and its excess held at zero
    leaks: dict[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.family not in FAMILIES:
            raise ConfigError(
                f"friction family {self.family!r} is not one of {', '.join(FAMILIES)} or lugre"
            )
        if self.stribeck and not self.shapes:
            self.shapes = {d: (W_S_START, DELTA_START) for d in self.directions}

    @property
    def stribeck(self) -> bool:
        return self.family.startswith("stribeck")

    @property
    def load(self) -> bool:
        """The family has a load term (its columns need the joint's load torque)."""
        return self.family.startswith("coulomb_viscous_load")

    @property
    def load_term(self) -> bool:
        """The joint's columns include the load's."""
        return self.load and not self.unloaded

    @property
    def directions(self) -> tuple[str, ...]:
        return _directions(self.family)

    @property
    def linear_names(self) -> list[str]:
        """Internal linear parameters: Coulomb, (Stribeck excess,) viscous per direction."""
        mid = ["excess"] if self.stribeck else ["load"] if self.load_term else []
        return [f"{n}{d}" for d in self.directions for n in ("coulomb", *mid, "viscous")]

    @property
    def names(self) -> list[str]:
        """The family's parameter names (:mod:`fricid.models`)."""
        base = ("tau_c", "tau_s", "w_s", "tau_v", "delta") if self.stribeck else ("f_c", "beta")
        if self.load:
            base = ("f_c", "f_ck", "beta")
        return [f"{n}{d}" for d in self.directions for n in base]

    def columns(self, v: np.ndarray, load: np.ndarray | None = None) -> np.ndarray:
        """The linear columns at velocities ``v`` (N,), shape (N, len(linear_names)); the
        load families need the joint's load torque ``load`` (N,) [N m]."""
        if self.load_term and load is None:
            raise ConfigError(f"the {self.family} family needs the joint's load torque")
        out = []
        for d in self.directions:
            ind, sgn = _mask(v, d)
            out.append(sgn)
            if self.stribeck:
                out.append(sgn * stribeck_shape(v, *self.shapes[d]))
            if self.load_term:
                out.append(sgn * np.abs(load))
            out.append(ind * v)
        return np.column_stack(out)

    def excess_column(self, v: np.ndarray, d: str, w_s, delta) -> np.ndarray:
        """The Stribeck column of direction ``d`` for shapes ``w_s``, ``delta`` (K,): (N, K)."""
        _, sgn = _mask(v, d)
        w = np.asarray(w_s, dtype=float)[None, :]
        e = np.asarray(delta, dtype=float)[None, :]
        return sgn[:, None] * np.exp(-((np.abs(v)[:, None] / w) ** e))

    def shape_jacobian(self, v: np.ndarray, linear: np.ndarray) -> np.ndarray:
        """d friction / d (w_s, delta) per direction, shape (N, 2 len(directions))."""
        out = []
        for k, d in enumerate(self.directions):
            w_s, delta = self.shapes[d]
            _, sgn = _mask(v, d)
            a = np.abs(v) / w_s
            with np.errstate(divide="ignore", invalid="ignore"):
                ad = a**delta
                e = np.exp(-ad)
                log_a = np.where(a > 0, np.log(np.where(a > 0, a, 1.0)), 0.0)
            excess = linear[3 * k + 1]
            out.append(sgn * excess * e * ad * delta / w_s)
            out.append(-sgn * excess * e * ad * log_a)
        return np.column_stack(out)

    def full_names(self) -> list[str]:
        """The internal linear names then the shapes: the order of :meth:`to_family`'s input."""
        shapes = [f"{n}{d}" for d in self.directions for n in ("w_s", "delta")]
        return self.linear_names + (shapes if self.stribeck else [])

    def to_family(self, values: np.ndarray, cov: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The family's parameters and their covariance from the internal ones (linear
        then shapes, :meth:`full_names`): ``tau_s = coulomb + excess``, the rest as they are."""
        internal = self.full_names()
        T = np.zeros((len(self.names), len(internal)))
        pos = {n: i for i, n in enumerate(internal)}
        for r, name in enumerate(self.names):
            base, d = split_direction(name)
            if base in ("tau_c", "f_c"):
                T[r, pos[f"coulomb{d}"]] = 1.0
            elif base == "f_ck" and self.unloaded:  # no load: not determined
                T[r, :] = np.nan
            elif base == "f_ck":
                T[r, pos[f"load{d}"]] = 1.0
            elif base == "tau_s":
                T[r, pos[f"coulomb{d}"]] = T[r, pos[f"excess{d}"]] = 1.0
            elif base in ("tau_v", "beta"):
                T[r, pos[f"viscous{d}"]] = 1.0
            else:
                T[r, pos[f"{base}{d}"]] = 1.0
        # a parameter the data do not determine (NaN) voids only the family's parameters
        # made from it, not the others (0 x NaN would)
        bad = np.isnan(np.diag(cov))
        voided = np.isnan(T).any(axis=1) | (np.nan_to_num(np.abs(T[:, bad])) > 0).any(axis=1)
        with np.errstate(invalid="ignore"):
            fam_values = T @ values
        T = np.nan_to_num(T)
        fam_cov = T @ np.nan_to_num(cov) @ T.T
        fam_cov[voided, :] = np.nan
        fam_cov[:, voided] = np.nan
        return fam_values, fam_cov


def excess_cap(tau: np.ndarray, gravity: np.ndarray) -> np.ndarray:
    """Per joint, the largest torque its drive applied beyond gravity, ``max_t |tau - g(q)|``
    [N m]: a joint that broke away met no static friction above it, so no Stribeck excess
    (``tau_s - tau_c``) above it is physical. Without it, a shape the data do not bound
    could take any excess: on a PD-tracked Panda (``benchmarks/bench_robot.py --truth sim
    --friction stribeck_asym``, seed 1) joint 1's ``w_s`` went to the box's 1 mrad/s with an
    excess of 16,000 N m (truth 0.15), a spike at the reversals the window leaves out that
    leaked through the low-pass into the held-out rows: 635 times the noise."""
    return np.max(np.abs(tau - gravity), axis=0)


def split_direction(name: str) -> tuple[str, str]:
    for d in ("_pos", "_neg"):
        if name.endswith(d):
            return name[: -len(d)], d
    return name, ""


def friction_for(joints: tuple[str, ...], friction) -> list[JointFriction]:
    """Each joint's :class:`JointFriction` from one family name or a mapping joint -> family
    (joints not named take ``stribeck_asym``)."""
    if isinstance(friction, str):
        return [JointFriction(friction) for _ in joints]
    if not isinstance(friction, dict):
        raise ConfigError(f"friction must be a family name or a mapping; got {friction!r}")
    unknown = sorted(set(friction) - set(joints))
    if unknown:
        raise ConfigError(f"friction names joints not in the model: {', '.join(unknown)}")
    return [JointFriction(friction.get(j, "stribeck_asym")) for j in joints]
