"""RWSAVSBAS: random-wandering, simulated-annealing, variable-step beetle antennae search.

References
----------
[R] B. Kou et al., "A New Parameter Identification Method for Industrial Robots with
    Friction", Machines 10(5) 349, 2022 (the RWSAVSBAS paper), sections 3.1-3.2 and 4.1.
[B] The BAS-RBFNN paper, eq. 18-20 (the beetle's direction, antennae and step).
[W] The wolf pack algorithm's scouting ("wandering") behaviour, the source of [R]'s
    ``G_best + sin(2 pi P / h) step`` (cited in [R] 3.1.1).
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from ..errors import ConfigError
from ._api import Budget, Solver, choice_option, clip01, positive_option, register
from ._bas import check_ratio, unit_directions

__all__ = ["RWSAVSBAS"]

_WANDER = ("antenna", "diagonal", "random")


@register
class RWSAVSBAS(Solver):
    """RWSAVSBAS as [R] sections 3 and 4.1 describe it, batched over runs.

    All lengths are in unit-box units; candidates are clipped to the box. Per run:

    * start: ``x = G = x0`` (or uniform in the box), evaluated (1 evaluation);
      ``step = step0``, ``T = T0``.
    * **outer loop** ``k = 1 .. n_outer`` ([R] 3.2 A-E), each with an **inner loop**
      ``p = 1 .. n_inner`` (``Q``) of three evaluations ([R] 3.2 B: "the fitness values of the
      three antennae"):

      1. ``b`` from eq. 18 of [B]; antennae ``x_r = x + (step / c) b``, ``x_l = x - (step / c) b``
         (eq. 19; [R] 4.1: ratio of step to antenna distance ``c = 3``);
      2. the wandering antenna ``x_w = G + sin(2 pi P / h_inner) step w`` ([R] 3.1.1);
      3. the BAS solution ``x_B = x - step b sign(f(x_r) - f(x_l))`` (eq. 20 of [B], for
         minimisation), credited with the value of the better antenna,
         ``f_B = min(f(x_r), f(x_l))`` (it is not evaluated: three evaluations per inner
         iteration);
      4. Metropolis ([R] 3.1.2): the beetle continues from the wandering point if
         ``f(x_w) <= f_B`` or, when worse, with probability ``exp(-(f(x_w) - f_B) / T)``
         (tested as ``f(x_w) - f_B < -T log U``); otherwise from ``x_B``;
      5. the global best ``G`` becomes the best of the three antennae when that is better.

      After the inner loop ([R] 3.2 D): one outer wandering point
      ``G + sin(2 pi k / h_outer) step w`` is evaluated and kept if better; then
      ``step <- eta step`` ([R] 3.1.3) and ``T <- cooling T``.

    That is ``1 + n_outer (3 n_inner + 1)`` evaluations (301,001 at the paper's settings).
    The result is the best point evaluated.

    Readings of what [R] leaves open (each one an option, so the benchmark shows the others):

    * ``wander``: the direction ``w`` of the wandering step. [R] writes a scalar times
      ``step``. ``"antenna"`` (default): along the beetle's current direction ``b`` (the third
      antenna shares the beetle's orientation; the outer wandering uses a fresh direction);
      ``"random"``: an independent random unit direction; ``"diagonal"``: the literal formula,
      the same offset added to every coordinate (``w = (1, ..., 1)``).
    * ``phase``: what ``P`` counts. ``"counter"`` (default): the iteration index of its loop,
      ``p`` inside (``h_inner = 100 = Q``: one sine period per inner loop) and ``k`` outside
      (``h_outer = 1000``: one period per run), as in the wolf pack algorithm's scouting where
      ``p`` indexes the ``h`` directions tried; ``"random"``: ``P`` uniform in ``[0, h)``.
    * ``best_update``: when ``G`` absorbs the inner loop's finds. ``"inner"`` (default): at
      once (``G`` is "the global optimal solution", [R] 3.1.1, and the wandering antenna
      circles the best point found so far); ``"outer"``: only at the end of each inner loop
      (a literal reading of [R] 3.2 D).
    * The Metropolis criterion compares the wandering point with the BAS solution (3.1.1: "the
      new solution obtained after the search is compared with the solution obtained by BAS to
      determine the subsequent direction of movement of the beetle").
    * ``T0 = 10000`` is far above the SSE scale (1e-4 .. 1), so for the first ~350 outer
      iterations every worse wandering point is accepted: the beetle keeps jumping back near
      ``G``. We keep the paper's value.

    Random numbers are drawn per run in one block of ``(Q + 1) x (2 d + 2)`` uniforms per outer
    iteration (so a run's stream does not depend on the other runs, the budget or the
    readings), and turned into directions, phases and Metropolis thresholds by numpy in one go.
    With an objective carrying a ``jit_kernel`` (:class:`~fricid.optim.JitObjective`) the
    inner loop then runs in compiled code (numba) on the same numbers (bit-identical to the
    numpy path when the kernel computes exactly what ``fun`` does); ``jit=False`` forces
    numpy.

    Options
    -------
    n_outer, n_inner : 1000, 100 ([R] 4.1).
    step0, eta, c : 0.1, 0.98, 3 ([R] 4.1).
    T0, cooling : 10000, 0.95 ([R] 4.1).
    h_inner, h_outer : 100, 1000 ([R] 4.1).
    wander, phase, best_update : the readings above.
    jit : "auto" (compiled when the objective has a kernel and numba is installed), True, False.
    xtol : the run has converged (status 0) when its last step ``step0 eta^(n_outer - 1)`` is
        at most this (1e-6, unit-box units; the paper's schedule ends at 1.7e-10); the
        schedule always runs to its end.
    """

    name = "rwsavsbas"
    batched = True
    summary = (
        "RWSAVSBAS (RWSAVSBAS paper 3-4.1): variable-step BAS with wandering antenna and "
        "Metropolis inner loop"
    )
    options: ClassVar[dict[str, Any]] = {
        "n_outer": 1000,
        "n_inner": 100,
        "step0": 0.1,
        "eta": 0.98,
        "c": 3.0,
        "T0": 10000.0,
        "cooling": 0.95,
        "h_inner": 100.0,
        "h_outer": 1000.0,
        "wander": "antenna",
        "phase": "counter",
        "best_update": "inner",
        "jit": "auto",
        "xtol": 1e-6,
    }

    def default_budget(self) -> int:
        o = self.opts
        return 1 + int(o["n_outer"]) * (3 * int(o["n_inner"]) + 1)

    def validate(self) -> None:
        o = self.opts
        for name in ("n_outer", "n_inner"):
            positive_option(o, name, self.name, integer=True)
        for name in ("step0", "T0", "h_inner", "h_outer"):
            positive_option(o, name, self.name)
        positive_option(o, "cooling", self.name, open_unit=True)
        check_ratio(o, self.name)
        choice_option(o, "wander", self.name, _WANDER)
        choice_option(o, "phase", self.name, ("counter", "random"))
        choice_option(o, "best_update", self.name, ("inner", "outer"))
        choice_option(o, "jit", self.name, ("auto", True, False))
        positive_option(o, "xtol", self.name, allow_zero=True)

    # -- the two paths -----------------------------------------------------------------------
    def _use_jit(self) -> bool:
        jit = self.opts["jit"]
        kernel = self.objective.kernel
        if jit is False or (jit == "auto" and kernel is None):
            return False
        if kernel is None:
            raise ConfigError(
                "option jit=True of method 'rwsavsbas' needs an objective with a compiled "
                "kernel (fricid.optim.JitObjective)"
            )
        try:
            from . import _rws_numba  # noqa: F401
        except ImportError:
            if jit is True:
                raise ConfigError(
                    "option jit=True of method 'rwsavsbas' needs numba, which is not installed"
                ) from None
            return False
        return True

    def run(self) -> tuple[int, str]:
        obj = self.objective
        o = self.opts
        R, d = obj.runs, obj.dim
        K, Q = int(o["n_outer"]), int(o["n_inner"])
        self._sin_in = np.sin(2.0 * np.pi * np.arange(1, Q + 1) / float(o["h_inner"]))
        x = self.start_points()
        f0 = obj(x[:, None, :])[:, 0]
        self.G, self.fG = x.copy(), f0.copy()
        self.ibu, self.ibf = x.copy(), np.full(R, np.inf)
        self.x = x
        self.step, self.T = float(o["step0"]), float(o["T0"])
        outer = self._outer_jit if self._use_jit() else self._outer_numpy
        for k in range(1, K + 1):
            blk = np.stack([g.random((Q + 1, 2 * d + 2)) for g in self.rngs])
            self.ibf[:] = np.inf
            outer(k, blk, *self._draws(k, blk))
            self.step *= float(o["eta"])
            self.T *= float(o["cooling"])
            self.nit = k
            obj.notify(k)
        last = float(o["step0"]) * float(o["eta"]) ** (K - 1)
        self.converged = last <= float(o["xtol"])
        return K, f"{K} outer iterations done, last step {last:.3g} (xtol {o['xtol']:g})"

    def _draws(self, k: int, blk: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The phases ``S (R, Q + 1)`` of the wandering steps and the Metropolis thresholds
        ``thr (R, Q)``: a worse wandering point is accepted when ``f(x_w) - f_B < thr``,
        i.e. ``U < exp(-(f(x_w) - f_B) / T)`` written as ``-T log U``."""
        d = self.objective.dim
        if self.opts["phase"] == "random":
            S = np.sin(2.0 * np.pi * blk[:, :, d + 1])
        else:
            s_out = np.sin(2.0 * np.pi * k / float(self.opts["h_outer"]))
            S = np.broadcast_to(np.append(self._sin_in, s_out), blk.shape[:2]).copy()
        with np.errstate(divide="ignore"):
            thr = -self.T * np.log(blk[:, :-1, d])
        return S, thr

    def _directions(self, blk: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Beetle directions ``b`` (eq. 18) and wandering directions ``w``, ``(R, Q + 1, d)``."""
        d = self.objective.dim
        B = unit_directions(blk[:, :, :d])
        mode = self.opts["wander"]
        if mode == "antenna":
            return B, B
        if mode == "random":
            return B, unit_directions(blk[:, :, d + 2 : 2 * d + 2])
        return B, np.ones_like(B)

    def _outer_numpy(self, k: int, blk: np.ndarray, S: np.ndarray, thr: np.ndarray) -> None:
        """One outer iteration of every run with numpy (the generic path)."""
        obj = self.objective
        R = obj.runs
        rows = np.arange(R)
        x, G, fG = self.x, self.G, self.fG
        step = self.step
        dist = step / float(self.opts["c"])
        immediate = self.opts["best_update"] == "inner"
        B, W = self._directions(blk)
        SW = (S[:, :, None] * step) * W
        delta = np.zeros(R)
        P = np.empty((R, 3, x.shape[1]))
        for p in range(blk.shape[1] - 1):
            b = B[:, p]
            db = dist * b
            np.add(x, db, out=P[:, 0])
            np.subtract(x, db, out=P[:, 1])
            np.add(G, SW[:, p], out=P[:, 2])
            clip01(P, out=P)
            f = obj(P)
            fr, fl, fw = f[:, 0], f[:, 1], f[:, 2]
            fb = np.minimum(fr, fl)
            worse = fw > fb
            np.subtract(fw, fb, out=delta, where=worse)
            accept = ~worse | (delta < thr[:, p])
            sgn = (fr > fl).astype(float) - (fr < fl)
            x = np.where(accept[:, None], P[:, 2], clip01(x - step * sgn[:, None] * b))
            j = np.argmin(f, axis=1)
            fj = f[rows, j]
            if immediate:
                better = fj < fG
                if better.any():
                    fG[better] = fj[better]
                    G[better] = P[rows[better], j[better]]
            else:
                better = fj < self.ibf
                self.ibf[better] = fj[better]
                self.ibu[better] = P[rows[better], j[better]]
        self.x = x
        if not immediate:
            better = self.ibf < fG
            fG[better] = self.ibf[better]
            G[better] = self.ibu[better]
        xw = clip01(G + SW[:, -1])
        fw = obj(xw[:, None, :])[:, 0]
        better = fw < fG
        fG[better] = fw[better]
        G[better] = xw[better]

    def _outer_jit(self, k: int, blk: np.ndarray, S: np.ndarray, thr: np.ndarray) -> None:
        """One outer iteration of every run in compiled code (same algorithm and numbers)."""
        from ._rws_numba import first_call, function_of

        B, W = self._directions(blk)
        obj = self.objective
        o = self.opts
        R, d = obj.runs, obj.dim
        Q = blk.shape[1] - 1
        if not hasattr(self, "_buf"):
            self._buf = (
                np.empty((3 * R, d)),
                np.empty(3 * R),
                np.empty((R, 3, d)),
                np.empty(Q + 1, dtype=np.int64),
                np.empty((Q + 1, R)),
                function_of(obj.kernel, obj.kernel_data),
            )
        X, out, P, hist_n, hist_f, kernel = self._buf
        args = (
            kernel,
            obj.kernel_data,
            obj.lower,
            obj.span,
            self.x,
            self.G,
            self.fG,
            self.ibu,
            self.ibf,
            np.ascontiguousarray(B),
            np.ascontiguousarray(W),
            np.ascontiguousarray(S),
            np.ascontiguousarray(thr),
            float(self.step),
            float(o["c"]),
            bool(o["best_update"] == "inner"),
            int(obj.remaining),
            int(obj.nfev),
            obj.best_u,
            obj.best_f,
            X,
            out,
            P,
            hist_n,
            hist_f,
        )
        # the arguments keep their types for the whole run: after the first call, the
        # compiled entry point without numba's per-call type dispatch
        if getattr(self, "_entry", None) is None:
            (used, nh, hit), self._entry = first_call(args)
        else:
            used, nh, hit = self._entry(*args)
        obj.nfev += int(used)
        for i in range(int(nh)):
            obj._hist_n.append(int(hist_n[i]))
            obj._hist_f.append(hist_f[i].copy())
        if hit:
            raise Budget
