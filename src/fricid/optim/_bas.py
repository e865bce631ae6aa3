"""Beetle antennae search (BAS) and the shared loop of its single-beetle variants.

References
----------
[B] "An Optimized RBF Neural Network Based on Beetle Antennae Search Algorithm for Modeling
    the Static Friction in a Robotic Manipulator Joint" (the BAS-RBFNN paper), section 3.2,
    eq. 18-21.
[J] X. Jiang, S. Li, "BAS: Beetle Antennae Search Algorithm for Optimization Problems",
    arXiv:1710.10724, 2017 (the original algorithm and its reference code).
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from ..errors import ConfigError
from ._api import Solver, clip01, positive_option, register

__all__ = ["BAS", "BeetleSolver", "unit_directions"]

#: Random numbers are drawn in blocks of this many iterations (same stream for any budget).
BLOCK = 100


def unit_directions(raw: np.ndarray) -> np.ndarray:
    """Eq. 18 of [B]: ``b = rands(m, 1) / ||rands(m, 1)||`` with ``rands`` uniform in [-1, 1].

    ``raw`` holds uniforms in [0, 1) along the last axis; a zero vector stays zero.
    """
    r = 2.0 * raw - 1.0
    norm = np.sqrt(np.sum(r * r, axis=-1, keepdims=True))
    return r / np.maximum(norm, 1e-12)


class BeetleSolver(Solver):
    """One beetle per run, batched over runs (BAS, VSBAS, IBAS).

    Iteration ``t`` (0-based), in the unit box, for every run at once:

    1. ``b`` from eq. 18 of [B];
    2. antennae ``x_r = x + d_t b`` and ``x_l = x - d_t b`` (eq. 19), clipped to the box;
    3. evaluate ``x``, ``x_r``, ``x_l`` in one call (3 evaluations; the position is the point
       the previous step moved to, as in the reference code of [J] which evaluates it to keep
       the best point seen). With ``evaluate_position=False`` only the antennae are evaluated
       (2 evaluations), which is all eq. 18-21 of [B] need: the best point seen is then the
       best antenna (or the final position);
    4. step ``x <- x - delta_t b sign(f(x_r) - f(x_l))`` (eq. 20 written for minimisation),
       clipped to the box.

    After the last iteration the final position is evaluated (``3 n_iter + 1`` evaluations, or
    ``2 n_iter + 1`` without the position).
    Subclasses give the schedule ``(d_t, delta_t)`` through :meth:`schedule`. The result is the
    best point evaluated.

    Convergence: the schedule always runs to its end (budgets compare fairly); the run has
    converged (``status`` 0) when its last step ``delta_{n-1}`` was at most the option
    ``xtol`` (unit-box units, default 1e-6), i.e. the beetle no longer moved by more than
    that. A schedule whose step stays longer (IBAS's ``step_min``, a short ``n_iter``) ends
    with status 4, "iteration limit reached without convergence".
    """

    batched = True
    options: ClassVar[dict[str, Any]] = {"n_iter": 1000, "xtol": 1e-6}

    def per_iteration(self) -> int:
        return 3 if self.opts.get("evaluate_position", True) else 2

    def default_budget(self) -> int:
        return self.per_iteration() * int(self.opts["n_iter"]) + 1

    def validate(self) -> None:
        positive_option(self.opts, "n_iter", self.name, integer=True)
        positive_option(self.opts, "xtol", self.name, allow_zero=True)
        flag = self.opts.get("evaluate_position", True)
        if not isinstance(flag, bool | np.bool_):
            raise ConfigError(
                f"option 'evaluate_position' of method '{self.name}' must be True or False; "
                f"got {flag!r}"
            )

    def schedule(self, n: int) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover - abstract
        """Antenna lengths ``d_t`` and steps ``delta_t`` for ``t = 0 .. n-1``."""
        raise NotImplementedError

    def run(self) -> tuple[int, str]:
        obj = self.objective
        n_iter = int(self.opts["n_iter"])
        dist, step = self.schedule(n_iter)
        with_position = self.per_iteration() == 3
        x = self.start_points()
        raw = None
        for t in range(n_iter):
            if t % BLOCK == 0:
                raw = np.stack([g.random((BLOCK, obj.dim)) for g in self.rngs])
            b = unit_directions(raw[:, t % BLOCK])
            xr = x + dist[t] * b
            xl = x - dist[t] * b
            if with_position:
                f = obj(np.stack([x, xr, xl], axis=1))[:, 1:]
            else:
                f = obj(np.stack([xr, xl], axis=1))
            sgn = (f[:, 0] > f[:, 1]).astype(float) - (f[:, 0] < f[:, 1])
            x = clip01(x - step[t] * sgn[:, None] * b)
            self.nit = t + 1
            obj.notify(self.nit)
        obj(x[:, None, :])
        last = float(step[-1])
        self.converged = last <= float(self.opts["xtol"])
        return (
            n_iter,
            f"{n_iter} iterations done, last step {last:.3g} (xtol {self.opts['xtol']:g})",
        )


@register
class BAS(BeetleSolver):
    """Beetle antennae search, eq. 18-21 of [B] (original algorithm: [J]).

    Antenna length and step follow eq. 21: ``d_t = eta_d d_{t-1} + d_inc`` and
    ``delta_t = eta_step delta_{t-1}`` (the paper: 0.95, 0.01 and 0.95), starting from ``d0``
    and ``step0`` at the first iteration. All lengths are in unit-box units. [B] gives no
    initial values; ``d0 = 0.2`` is the fixed point ``d_inc / (1 - eta_d)`` of eq. 21 (so the
    antennae keep one length) and ``step0 = 0.5`` lets the beetle cross half the box at first.

    Options
    -------
    n_iter : iterations (1000); ``3 n_iter + 1`` evaluations.
    d0, step0 : initial antenna length and step (0.2, 0.5).
    eta_d, d_inc, eta_step : the constants of eq. 21 (0.95, 0.01, 0.95).
    evaluate_position : also evaluate the position each iteration, as [J]'s code (True), or
        only the two antennae, as eq. 18-21 (False; 2 evaluations per iteration).
    xtol : converged when the last step is at most this (1e-6; see :class:`BeetleSolver`).
    """

    name = "bas"
    summary = "beetle antennae search (BAS-RBFNN paper eq. 18-21), one beetle"
    options: ClassVar[dict[str, Any]] = {
        "n_iter": 1000,
        "d0": 0.2,
        "step0": 0.5,
        "eta_d": 0.95,
        "d_inc": 0.01,
        "eta_step": 0.95,
        "evaluate_position": True,
        "xtol": 1e-6,
    }

    def validate(self) -> None:
        super().validate()
        for name in ("d0", "step0"):
            positive_option(self.opts, name, self.name)
        for name in ("eta_d", "eta_step"):
            positive_option(self.opts, name, self.name, open_unit=True)
        positive_option(self.opts, "d_inc", self.name, allow_zero=True)

    def schedule(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        o = self.opts
        d = np.empty(n)
        s = np.empty(n)
        dt, st = float(o["d0"]), float(o["step0"])
        for t in range(n):
            d[t], s[t] = dt, st
            dt = o["eta_d"] * dt + o["d_inc"]
            st = o["eta_step"] * st
        return d, s


def check_ratio(opts: dict, method: str) -> None:
    """Shared checks of the variable-step variants (``eta`` in (0, 1), ``c`` > 0)."""
    positive_option(opts, "eta", method, open_unit=True)
    positive_option(opts, "c", method)
    if "step_min" in opts and not opts["step_min"] < opts["step_max"]:
        raise ConfigError(
            f"option 'step_min' of method '{method}' must be below 'step_max'; got "
            f"{opts['step_min']!r} >= {opts['step_max']!r}"
        )
