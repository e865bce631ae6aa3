"""The two seed papers' published numbers and figure captions, as data, in one place.

Reproductions (:mod:`fricid.report.reproduce`) put these beside ours; nothing else in
fricid should hard-code a paper's result.

References
----------
[B] "An Optimized RBF Neural Network Based on Beetle Antennae Search Algorithm for Modeling
    the Static Friction in a Robotic Manipulator Joint" (the BAS-RBFNN paper).
[R] Kou, Huang, Wang, Ren, Zhang, Guo, "A New Parameter Identification Method for Industrial
    Robots with Friction", Machines 10(5) 349, 2022 (the RWSAVSBAS paper).

Units are the papers' own: [B] gives torques in N m in Tables 3-4 but states no unit for
Table 1's RMSE (described one way everywhere by :func:`table1_rmse_unit`) and prints Table 2's
torque parameters on a scale unlike N m (the paper does not say). [R] gives no units; we read
its numbers as N m and rad/s.
"""

from __future__ import annotations

__all__ = ["BAS_RBFNN", "RWSAVSBAS", "table1_rmse_unit"]

#: The BAS-RBFNN paper [B].
BAS_RBFNN: dict = {
    "title": "An Optimized RBF Neural Network Based on Beetle Antennae Search Algorithm for "
    "Modeling the Static Friction in a Robotic Manipulator Joint",
    "short": "BAS-RBFNN paper",
    # section 2.2 and Fig. 1: tau_g = p_x cos(theta) - p_y sin(theta), eq. 7
    "gravity": {"p_x": 0.2011, "p_y": 0.06175},
    "design": {
        "positions_deg": (-60.0, -20.0, 2.0),
        "velocities_deg_s": (0.1, 0.3, 0.5, 1.0, 2.0, 4.0, 6.0, 9.0, 13, 18, 24, 31, 38, 44, 50),
        "temperatures_degC": (5.0, 45.0, 2.0),
        "repetitions": 10,
        "sample_rate_hz": 250.0,
    },
    # Table 1: "Performance indicators for the models" (columns eq. 2, eq. 3, eq. 4)
    "table1": {
        "stribeck": {"label": "Velocity", "fitness": 0.8732, "rmse": 35.25, "rmspe": 0.1792},
        "msk": {"label": "Velocity-load", "fitness": 0.9418, "rmse": 24.16, "rmspe": 0.1077},
        "vlt": {
            "label": "Velocity-temperature-load",
            "fitness": 0.9783,
            "rmse": 6.103,
            "rmspe": 0.02312,
        },
    },
    # Table 2: parameters of the velocity-load-temperature model, eq. 4, in fricid's names
    "table2": {
        "f_c": (68.74, "f_c"),
        "f_ctl": (0.2165, "f_cτl"),
        "f_stl": (0.0436, "f_sτl"),
        "f_v0": (298.7, "f_v0"),
        "f_vT": (-1.6240, "f_vT"),
        "v_tl0": (2.852, "θ̇_τ0"),
        "v_v0": (13.46, "θ̇_v0"),
        "v_vT": (4.218, "θ̇_vT"),
    },
    # Table 3: absolute prediction error [N m] on all data (the training set)
    "table3": {
        "rbfnn": {"label": "RBFNN", "mean": 0.0029, "max": 0.008},
        "bas_rbfnn": {"label": "BAS-RBFNN", "mean": 0.0011, "max": 0.0052},
        "vlt": {"label": "Velocity-load-temperature model", "mean": 0.0058, "max": 0.0142},
    },
    # Table 4: GA-RBFNN against BAS-RBFNN [N m]
    "table4": {
        "ga_rbfnn": {"label": "GA-RBFNN", "mean": 0.0012, "max": 0.0054},
        "bas_rbfnn": {"label": "BAS-RBFNN", "mean": 0.0011, "max": 0.0052},
    },
    # Fig. 9: training MSE target and the epoch each method reached it
    "fig9": {"target_mse": 1e-4, "epochs": {"ga_rbfnn": 356, "bas_rbfnn": 257}},
    # Fig. 10 / section 4.4: the unseen region and the errors there [N m]
    "fig10": {
        "velocities_deg_s": (52.0, 60.0, 2.0),
        "positions_deg": (-22.0, -10.0, 2.0),
        "temperatures_degC": (45.0, 55.0, 2.0),
        "max": 0.0063,
        "mean": 0.0012,
    },
    "figures": {
        "fig1": "Gravitational torque fitting curve (eq. 7 fitted by least squares; "
        "p_x = 0.2011, p_y = 0.06175).",
        "fig6": "Two combined factors dependence of friction: (a) load and velocity, "
        "(b) temperature and velocity, (c) temperature and load. The Stribeck dip is prominent "
        "at low speed and viscous friction dominates at high speed (a); friction falls with "
        "rising temperature (b); it rises with the gravity load (c).",
        "fig7": "Performance indicators (fitness, RMSE, RMSPE, normalised) for the "
        "velocity, velocity-load and velocity-temperature-load models: temperature and load "
        "both matter.",
        "fig8": "Predicted and practical static friction and the prediction errors of (a, b) "
        "RBFNN, (c, d) BAS-RBFNN, (e, f) the velocity-load-temperature model; mean errors "
        "0.0029, 0.0011 and 0.0058 N m.",
        "fig9": "Training MSE of (a) GA-RBFNN and (b) BAS-RBFNN; the target MSE 1e-4 is reached "
        "at epoch 356 by GA and 257 by BAS.",
        "fig10": "Prediction errors of BAS-RBFNN beyond the experimental area (52-60 deg/s, "
        "positions -22 to -10 deg, 45-55 degC): maximum 0.0063 N m, mean 0.0012 N m.",
    },
}

#: The RWSAVSBAS paper [R].
RWSAVSBAS: dict = {
    "title": "A New Parameter Identification Method for Industrial Robots with Friction",
    "short": "RWSAVSBAS paper",
    "n_samples": 17,
    "runs": 8,
    "iterations": 1000,
    # section 4.1
    "settings": {
        "rwsavsbas": {
            "step0": 0.1,
            "T0": 10000.0,
            "anneal": 0.95,
            "Q": 100,
            "h_inner": 100,
            "h_outer": 1000,
            "eta": 0.98,
            "step_to_d0": 3.0,
            "c": 3.0,
        },
        "vsbas": {"step0": 0.1, "eta": 0.98},
        "ibas": {"step_max": 0.3, "step_min": 0.1},
    },
    # Table 1: fitness = SSE over the 17 samples (eq. 11), over 8 runs
    "table1": {
        "vsbas": {"label": "VSBAS", "mean": 0.60, "max": 1.86, "min": 0.10},
        "ibas": {"label": "IBAS", "mean": 0.42, "max": 0.83, "min": 0.09},
        "rwsavsbas": {"label": "RWSAVSBAS", "mean": 0.00013, "max": 0.00014, "min": 0.00013},
    },
    # Table 2: the Stribeck parameters of the best RWSAVSBAS run (delta fixed to 1)
    "table2": {"tau_c": 0.084, "tau_s": 0.641, "w_s": 0.066, "tau_v": 0.0026},
    # Fig. 7 (text of section 4.3.2): errors at the best run of each algorithm [N m]
    "fig7": {"vsbas_ibas_max": 0.15, "vsbas_ibas_overall": 0.08},
    "figures": {
        "fig3": "Friction torque of the industrial robot (joint 3) against velocity: the "
        "sampled friction rises in the low-speed section (the Stribeck effect).",
        "fig4": "The Stribeck model: tau_s at zero speed; the high-speed tangent meets the "
        "torque axis at tau_c with slope tau_v; w_s is where the zero-speed tangent meets the "
        "tau_c level.",
        "fig6": "Average fitness (SSE) curves of VSBAS, IBAS and RWSAVSBAS over 8 runs of "
        "1000 iterations: RWSAVSBAS converges fastest, VSBAS slowest early on.",
        "fig7": "Friction torque error at each sampling point for each algorithm's best run: "
        "VSBAS and IBAS up to about 0.15 N m (about 0.08 overall), RWSAVSBAS near zero.",
        "fig8": "Friction torque predicted by RWSAVSBAS (Table 2 parameters, red line) over "
        "the measured friction: the trend matches at low and high speed.",
    },
}


def table1_rmse_unit() -> str:
    """How fricid reads [B] Table 1's RMSE, in one sentence used wherever it is shown.

    The paper states no unit; its velocity-load-temperature RMSE is close to its Table 3 mean
    error of the same model in mN m, and a thousand times its N m value, so we read it as mN m.
    """
    rmse = BAS_RBFNN["table1"]["vlt"]["rmse"]
    mean_mnm = 1e3 * BAS_RBFNN["table3"]["vlt"]["mean"]
    return (
        "The paper states no unit for its Table 1 RMSE; we read it as mN m (its "
        f"velocity-load-temperature RMSE {rmse:g} is close to its Table 3 mean error of "
        f"{mean_mnm:.2g} mN m for that model, whose errors Table 3 gives in N m)."
    )
