"""A real-coded genetic algorithm (GA), for the BAS-RBFNN paper's GA-RBFNN comparison.

References
----------
[B] The BAS-RBFNN paper, section 4.3 (GA-RBFNN against BAS-RBFNN; the paper does not give
    its GA's operators).
[D] K. Deb, R. B. Agrawal, "Simulated binary crossover for continuous search space",
    Complex Systems 9, 1995 (SBX); K. Deb, M. Goyal, "A combined genetic adaptive search
    (GeneAS) for engineering design", 1996 (polynomial mutation).
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from ..errors import ConfigError
from ._api import Solver, choice_option, positive_option, register

__all__ = ["GA"]


@register
class GA(Solver):
    """Real-coded generational GA with elitism, batched over runs, in the unit box.

    Each generation: binary tournaments pick parents, simulated binary crossover (SBX, [D])
    with probability ``p_cross`` per pair (each variable swapped with probability 0.5),
    polynomial mutation ([D]) of each gene with probability ``p_mut`` (default ``1 / d``),
    children clipped to the box; the ``n_elite`` best parents survive unchanged (not
    re-evaluated), so each generation costs ``pop_size - n_elite`` evaluations, less its
    clones: a child that neither crossover nor mutation changed is its parent, whose value is
    known, so it is neither evaluated nor counted (option ``dedupe``, default True; issue 14
    measured 7 % of the evaluations spent on clones). [B] does not describe its GA; these are
    the textbook real-coded operators.

    Options
    -------
    pop_size : 40.  n_elite : 2.  tournament : 2.
    p_cross, eta_c : 0.9, 15 (SBX).  p_mut, eta_m : None (= 1 / d), 20 (polynomial mutation).
    n_gen : generations, or None to run until the budget is spent (default budget 4000).
    init_spread : None (the population uniform in the box, ``x0`` one member), or the standard
        deviation (unit-box units) of a population drawn around ``x0`` (``x0`` itself one member;
        the others ``x0 + init_spread * N(0, 1)``, clipped), the start a local method gets.
    stall, ftol : the convergence criterion, off by default (``stall=None``): the run stops,
        converged (status 0), when the best value improved by at most ``ftol`` times its
        magnitude over the last ``stall`` generations (ftol 1e-8). Without it the GA ends at
        ``n_gen`` (status 4) or the budget (status 1), never "converged". With ``stall`` the
        runs of :func:`~fricid.optim.minimize_runs` are made one after another (each stops on
        its own), not in lockstep.
    dedupe : True: clones are not re-evaluated (above). Each run then has its own count of
        evaluations, so the runs of :func:`~fricid.optim.minimize_runs` are made one after
        another; ``dedupe=False`` evaluates (and counts) every child, runs in lockstep.
    """

    name = "ga"
    summary = "real-coded genetic algorithm (SBX, polynomial mutation, elitism)"
    batched = True
    default_evals = 4000
    options: ClassVar[dict[str, Any]] = {
        "pop_size": 40,
        "n_elite": 2,
        "tournament": 2,
        "p_cross": 0.9,
        "eta_c": 15.0,
        "p_mut": None,
        "eta_m": 20.0,
        "n_gen": None,
        "stall": None,
        "ftol": 1e-8,
        "dedupe": True,
        "init_spread": None,
    }

    def validate(self) -> None:
        o = self.opts
        for name in ("pop_size", "tournament"):
            positive_option(o, name, self.name, integer=True)
        positive_option(o, "n_elite", self.name, integer=True, allow_zero=True)
        if o["pop_size"] < 2 or o["n_elite"] >= o["pop_size"]:
            raise ConfigError(
                f"method 'ga' needs pop_size >= 2 and n_elite < pop_size; got pop_size "
                f"{o['pop_size']!r}, n_elite {o['n_elite']!r}"
            )
        for name in ("p_cross", "eta_c", "eta_m") + (() if o["p_mut"] is None else ("p_mut",)):
            positive_option(o, name, self.name, allow_zero=True)
        for name in ("p_cross", "p_mut"):
            if o[name] is not None and o[name] > 1:
                raise ConfigError(
                    f"option '{name}' of method 'ga' is a probability in [0, 1]; got {o[name]!r}"
                )
        if o["n_gen"] is not None:
            positive_option(o, "n_gen", self.name, integer=True)
        if o["stall"] is not None:
            positive_option(o, "stall", self.name, integer=True)
            self.batched = False  # each run stops on its own
        positive_option(o, "ftol", self.name, allow_zero=True)
        choice_option(o, "dedupe", self.name, (True, False))
        if o["dedupe"]:
            self.batched = False  # each run counts its own evaluations
        self.n_clones = 0
        if o["init_spread"] is not None:
            positive_option(o, "init_spread", self.name)

    def run(self) -> tuple[int, str]:
        obj = self.objective
        o = self.opts
        R, d = obj.runs, obj.dim
        P, E, t = int(o["pop_size"]), int(o["n_elite"]), int(o["tournament"])
        n_off = P - E
        n_pairs = (n_off + 1) // 2
        p_mut = 1.0 / d if o["p_mut"] is None else float(o["p_mut"])
        ec, em = float(o["eta_c"]), float(o["eta_m"])
        rows = np.arange(R)[:, None]

        pop = np.stack([g.random((P, d)) for g in self.rngs])
        if self.x0 is not None:
            u0 = obj.to_u(self.x0)
            if o["init_spread"] is not None:  # the population around x0, as a local start
                noise = np.stack([g.standard_normal((P, d)) for g in self.rngs])
                pop = np.clip(u0[..., None, :] + float(o["init_spread"]) * noise, 0.0, 1.0)
            pop[:, 0] = u0
        fit = obj(pop)
        n_gen = o["n_gen"]
        stall = None if o["stall"] is None else int(o["stall"])
        best = [float(np.min(fit))]
        gen = 0
        while n_gen is None or gen < int(n_gen):
            draws = [
                (
                    g.integers(0, P, size=(2 * n_pairs, t)),
                    g.random((n_pairs, 2 * d + 1)),
                    g.random((2 * n_pairs, 2 * d)),
                )
                for g in self.rngs
            ]
            cand = np.stack([a for a, _, _ in draws])  # (R, 2 n_pairs, t)
            cross = np.stack([b for _, b, _ in draws])  # (R, n_pairs, 2 d + 1)
            mut = np.stack([c for _, _, c in draws])  # (R, 2 n_pairs, 2 d)
            # binary tournaments: the first of the best among t random members
            cf = fit[rows[:, :, None], cand]
            win = np.take_along_axis(cand, np.argmin(cf, axis=2)[:, :, None], axis=2)[:, :, 0]
            parents = pop[rows, win]  # (R, 2 n_pairs, d)
            p1, p2 = parents[:, 0::2], parents[:, 1::2]
            # SBX
            u = cross[:, :, d + 1 :]
            beta = np.where(
                u <= 0.5,
                (2.0 * u) ** (1.0 / (ec + 1.0)),
                (1.0 / (2.0 * (1.0 - u))) ** (1.0 / (ec + 1.0)),
            )
            do = (cross[:, :, :1] < o["p_cross"]) & (cross[:, :, 1 : d + 1] < 0.5)
            c1 = np.where(do, 0.5 * ((1.0 + beta) * p1 + (1.0 - beta) * p2), p1)
            c2 = np.where(do, 0.5 * ((1.0 - beta) * p1 + (1.0 + beta) * p2), p2)
            kids = np.empty_like(parents)
            kids[:, 0::2], kids[:, 1::2] = c1, c2
            # polynomial mutation (range 1 in the unit box)
            um = mut[:, :, d:]
            delta = np.where(
                um < 0.5,
                (2.0 * um) ** (1.0 / (em + 1.0)) - 1.0,
                1.0 - (2.0 * (1.0 - um)) ** (1.0 / (em + 1.0)),
            )
            kids = np.clip(np.where(mut[:, :, :d] < p_mut, kids + delta, kids), 0.0, 1.0)
            kids = kids[:, :n_off]
            order = np.argsort(fit, axis=1, kind="stable")[:, :E]
            elite, elite_f = pop[rows, order], fit[rows, order]
            kid_f = self._evaluate(kids, parents[:, :n_off], fit[rows, win][:, :n_off])
            pop = np.concatenate([elite, kids], axis=1)
            fit = np.concatenate([elite_f, kid_f], axis=1)
            gen += 1
            self.nit = gen
            obj.notify(gen)
            if stall is not None:
                best.append(float(np.min(fit)))
                if gen >= stall and best[-stall - 1] - best[-1] <= float(o["ftol"]) * abs(
                    best[-stall - 1]
                ):
                    self.converged = True
                    return gen, f"best value stalled for {stall} generations after {gen}"
        return gen, f"{gen} generations done"

    def _evaluate(self, kids: np.ndarray, parents: np.ndarray, parent_f: np.ndarray) -> np.ndarray:
        """The children's values ``(R, n)``: evaluated, except (with ``dedupe``, one run) the
        clones of their parent, which take its known value uncounted."""
        if not self.opts["dedupe"]:
            return self.objective(kids)
        new = ~np.all(kids[0] == parents[0], axis=1)
        self.n_clones += int(new.size - np.count_nonzero(new))
        kid_f = parent_f.copy()
        if new.any():
            kid_f[0, new] = self.objective(kids[:, new])[0]
        return kid_f
