"""The simulation routes of trajectory identification (``two_stage``, ``joint``): LuGre's
sigma_0 and sigma_1 by simulation error in windows around the low-speed stretches (multiple
shooting), the notes of :mod:`fricid.identify.dynamic.trajectory` say why and how.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ...models import lugre
from ._routes import JOINT_PARAMS, _refine_static, _sim_bounds, _SimProblem, _simulation, _windows

__all__ = ["REFINE", "SEGMENT", "WINDOW_AFTER", "WINDOW_BEFORE", "simulation_route"]

#: Seconds a simulation window opens before a low-speed stretch and closes after it.
WINDOW_BEFORE = 0.02
WINDOW_AFTER = 0.06

#: Seconds of one simulated segment: each starts again from the measured motion (multiple
#: shooting). Open-loop, a joint near break-away is so sensitive to the torque that a
#: simulation over a whole window can stay stuck where the joint broke away (or the reverse)
#: and never recover; the bristle dynamics play out within a few milliseconds, well inside a
#: segment.
SEGMENT = 0.025

#: Passes of the refinement (static part with LuGre's friction along the motion, then
#: sigma_0 and sigma_1 again) after the two-stage estimate; 0 for the plain two-stage route.
REFINE = 1


def simulation_route(
    series,
    vf: np.ndarray,
    acc: np.ndarray,
    mask: np.ndarray,
    fit: dict[str, Any],
) -> tuple[dict[str, Any], dict[str, Any]]:
    """The ``two_stage`` and ``joint`` routes: sigma_0, sigma_1 by simulation error in windows
    around the low-speed stretches, after the regression's static part (the notes of
    :mod:`.trajectory`), refined :data:`REFINE` times; ``joint`` then every parameter at once.

    ``fit`` holds the state of :func:`.trajectory.fit_trajectory` (the regression's stage,
    its tables, the options); its ``stages``, ``fits`` (each search, named, in order),
    ``final`` and ``bounds_out`` are updated in place. Returns the provenance's simulation
    record and the static table.
    """
    rate = 1.0 / series.dt
    stage1, static, rename = fit["stage1"], fit["static"], fit["rename"]
    static_tab, joint_vals = fit["static_tab"], fit["joint_vals"]
    stages, fits, final, bounds_out = (
        fit["stages"],
        fit["fits"],
        fit["final"],
        fit["bounds_out"],
    )
    method, seed, max_evals, n_sub = fit["method"], fit["seed"], fit["max_evals"], fit["n_sub"]
    gravity, route, v_slide, v_window = (
        fit["gravity"],
        fit["route"],
        fit["v_slide"],
        fit["v_window"],
    )
    cluster_n = fit["cluster_n"]
    base = np.array(
        [1e4, 1.0]
        + [static_tab[n]["value"] for n in lugre.PARAM_NAMES[2:]]
        + [joint_vals["inertia"], joint_vals["p_x"], joint_vals["p_y"]]
    )
    w_s = static_tab["w_s"]["value"]
    v_win = v_window if v_window is not None else max(w_s, 2.0 * v_slide)
    w = _windows(
        series,
        vf,
        acc,
        v_win,
        int(WINDOW_BEFORE * rate),
        int(WINDOW_AFTER * rate),
        max(int(SEGMENT * rate), 4),
    )
    dynamic = ["sigma_0", "sigma_1"]
    b2 = _sim_bounds(dynamic, w, stage1, rename)
    problem = _SimProblem(w, base, dynamic, n_sub, b2)
    held = [rename.get(n, n) for n in stage1.names] if static is None else list(stage1.names)
    problem.set_scale(problem.full(b2.mean(axis=1)))
    stage2 = _simulation(problem, b2.mean(axis=1), method, seed, max_evals, first=(stage1, held))
    fits.append(("simulation", stage2))
    for k in range(REFINE if static is None else 0):
        # the static part again with LuGre's friction along the motion, then sigma_0,
        # sigma_1 again from there (module notes: "Refinement")
        ref = _refine_static(
            series,
            vf,
            acc,
            mask,
            stage2,
            stage1,
            gravity,
            method,
            seed,
            max_evals,
            cluster_n,
        )
        stages[f"refinement_{k + 1}"] = ref
        fits.append((f"refinement_{k + 1}", ref))
        static_tab = {rename.get(n, n): row for n, row in ref.table().items()}
        final.update(static_tab)
        joint_vals.update({n: static_tab[n]["value"] for n in JOINT_PARAMS if n in static_tab})
        problem.base = np.array(
            [*stage2.values]
            + [static_tab[n]["value"] for n in lugre.PARAM_NAMES[2:]]
            + [joint_vals["inertia"], joint_vals["p_x"], joint_vals["p_y"]]
        )
        held = [rename.get(n, n) for n in ref.names]
        stage2 = _simulation(
            problem,
            problem.to_u(stage2.values),
            method,
            seed,
            max_evals,
            first=(ref, held),
        )
        fits.append((f"simulation after refinement_{k + 1}", stage2))
    stages["simulation"] = stage2
    for n, row in stage2.table().items():
        final[n] = row
    bounds_out.update({n: list(b) for n, b in zip(stage2.names, stage2.bounds, strict=True)})
    if route == "joint":
        base = problem.full(problem.to_u(stage2.values))[0]
        names = list(lugre.PARAM_NAMES) + list(JOINT_PARAMS[: 1 if gravity == "none" else 3])
        tab = {**static_tab, **{n: {"value": v} for n, v in joint_vals.items()}}
        b3 = []
        for n in names:
            if n in dynamic:
                b3.append(b2[dynamic.index(n)])
            elif n in bounds_out:
                b3.append(bounds_out[n])
            else:
                b3.append(_sim_bounds(names, w, stage1, rename)[names.index(n)])
        b3 = np.array(b3, dtype=float)
        problem3 = _SimProblem(w, base, names, n_sub, b3)
        problem3.scale = problem.scale
        x3 = np.clip(
            problem3.to_u(base[[problem3.names.index(n) for n in names]]),
            b3[:, 0],
            b3[:, 1],
        )
        stage3 = _simulation(problem3, x3, method, seed, max_evals)
        stages["simulation_joint"] = stage3
        fits.append(("simulation_joint", stage3))
        del tab
        for n, row in stage3.table().items():
            final[n] = row
    sim_info: dict[str, Any] = {
        "windows": w.count,
        "window_samples": int(w.index.size),
        "v_window": float(v_win),
        "n_sub": int(n_sub),
    }
    return sim_info, static_tab
