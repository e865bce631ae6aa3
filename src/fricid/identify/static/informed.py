"""Parameters outside the range the data can inform: a Stribeck velocity below the slowest
measured speed, a Coulomb level that only the extrapolation reaches.

A fit can give such a parameter a finite standard error (the Jacobian is not singular: the
parameter still moves the curve a little over the measured speeds), and it is still not
determined by the data in any useful sense. In the Stribeck curve ([B] eq. 2, [R] eq. 7;
[B] eq. 3 for M_sk)

``F = sign(v) [F_c + (F_s - F_c) exp(-|v / v_s|^delta)] + viscous``

the static level ``F_s`` and the Stribeck velocity ``v_s`` are seen only where the
exponential term is still visible at the slowest measured speed, and the Coulomb level
``F_c`` only where it has decayed by the fastest one. :func:`uninformed` names:

- ``F_s`` and ``v_s`` when the term has fallen below :data:`SEEN` (5 %) of its height at the
  slowest measured speed (the Stribeck velocity lies below the data);
- ``F_c`` when the term is still above :data:`DECAYED` (20 %) of its height at the fastest
  measured speed, and that height is not negligible (above :data:`SEEN` of the larger
  level): the Coulomb level is where the curve would go beyond the data.

Per direction for the ``_asym`` families (parameters ending in ``_pos`` or ``_neg``, speeds of
that direction).
"""

from __future__ import annotations

import numpy as np

from ...models import get_model
from ...samples import FrictionSamples

__all__ = ["DECAYED", "SEEN", "uninformed"]

#: The Stribeck term below this share of its height at the slowest measured speed: not seen.
SEEN = 0.05
#: The Stribeck term above this share of its height at the fastest measured speed: the
#: Coulomb level not reached.
DECAYED = 0.2

#: Coulomb level, static level, Stribeck velocity, exponent, by family.
_TERMS = (("tau_c", "tau_s", "w_s", "delta"), ("f_c", "f_s", "v_s", "xi"))


def _speeds(samples: FrictionSamples, suffix: str) -> np.ndarray:
    v = samples.velocity
    d = samples.direction
    if suffix == "_pos":
        keep = (d == 1) | ((d == 0) & (v > 0))
    elif suffix == "_neg":
        keep = (d == -1) | ((d == 0) & (v < 0))
    else:
        keep = np.ones(v.size, bool)
    s = np.abs(v[keep])
    return s[s > 0]


def uninformed(model_name: str, theta: np.ndarray, samples: FrictionSamples) -> dict[str, str]:
    """Notes (``"not determined: ..."``) for the parameters of ``model_name`` at ``theta``
    that lie outside the range the measured speeds of ``samples`` can inform (module notes);
    empty for families without a Stribeck term."""
    model = get_model(model_name)
    names = list(model.param_names)
    values = dict(zip(names, np.asarray(theta, dtype=float), strict=True))
    out: dict[str, str] = {}
    for suffix in ("", "_pos", "_neg"):
        for coulomb, static, vel, expo in _TERMS:
            keys = [k + suffix for k in (coulomb, static, vel, expo)]
            if not all(k in values for k in keys):
                continue
            speeds = _speeds(samples, suffix)
            if not speeds.size:
                continue
            c, top, w, e = (values[k] for k in keys)
            w = abs(w)
            if w <= 0:
                continue
            slow, fast = float(speeds.min()), float(speeds.max())
            seen = float(np.exp(-((slow / w) ** e)))
            left = float(np.exp(-((fast / w) ** e)))
            if seen < SEEN:
                why = (
                    f"not determined: the Stribeck velocity {w:.3g} rad/s lies below the "
                    f"slowest measured speed {slow:.3g} rad/s (the Stribeck term is at "
                    f"{seen:.1%} of its height there), so the data do not see it"
                )
                out[keys[1]] = why
                out[keys[2]] = why
            if left > DECAYED and abs(top - c) > SEEN * max(abs(c), abs(top)):
                out[keys[0]] = (
                    f"not determined: the Stribeck term is still at {left:.0%} of its height at "
                    f"the fastest measured speed {fast:.3g} rad/s (Stribeck velocity {w:.3g} "
                    "rad/s), so the Coulomb level is an extrapolation beyond the data"
                )
    return out
