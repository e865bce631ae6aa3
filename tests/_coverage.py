"""How many trials a coverage test needs, and its pass mark: the binomial gate.

A test that counts how many of ``n`` nominal 95 % intervals cover the truth must (a) fail a
calibrated method rarely and (b) fail a miscalibrated one almost always. :func:`gate` gives
the pass mark ``k`` (at least ``k`` of ``n`` must cover) for which a calibrated method fails
with probability at most ``false_alarm``, and the chance that a method whose intervals cover
only ``bad`` passes anyway. :func:`fewest_trials` is the smallest ``n`` whose gate lets a
method covering ``bad`` through with probability at most ``miss``: with the defaults (1 %
false alarms; 80 % coverage, i.e. half-widths about 0.65 of the right ones, let through at
most 5 % of the time) it is 69 trials, pass mark 61. The trials are taken as independent;
several parameters of one fit are not quite, so a test counts seeds x parameters at least.
"""

from __future__ import annotations

from scipy.stats import binom

__all__ = ["fewest_trials", "gate"]


def gate(n: int, nominal: float = 0.95, false_alarm: float = 0.01) -> tuple[int, float]:
    """The pass mark ``k`` for ``n`` trials and the false-alarm rate it gives:
    ``P(X < k) <= false_alarm`` for ``X ~ Binomial(n, nominal)``, ``k`` the largest such."""
    k = n
    while k > 0 and binom.cdf(k - 1, n, nominal) > false_alarm:
        k -= 1
    return k, float(binom.cdf(k - 1, n, nominal))


def fewest_trials(
    bad: float = 0.80, miss: float = 0.05, nominal: float = 0.95, false_alarm: float = 0.01
) -> tuple[int, int]:
    """The fewest trials ``n`` (and their pass mark) whose :func:`gate` passes a method that
    covers only ``bad`` with probability at most ``miss``."""
    for n in range(1, 10_000):
        k, _ = gate(n, nominal, false_alarm)
        if binom.sf(k - 1, n, bad) <= miss:
            return n, k
    raise ValueError("no number of trials separates these coverages")
