"""Run a scenario on the virtual joint: raw logs, as the BAS-RBFNN paper's experiment records them.

For each temperature (one experiment), each velocity set-point and each repetition, one period
is simulated: dwell, forward traverse, dwell, backward traverse (:class:`~.design.Traverse`),
sampled at the design's rate. The log carries the motor current ``I = tau_m / K`` (eq. 8, 13)
with sensor noise, ADC quantisation and spikes, the measured velocity, the encoder position and
the temperature channel. A scenario with :class:`~.faults.Faults` adds the faults of a real
campaign (rest with float-residue velocity, settling transients, creeping ramps, return moves,
spike bursts, sensor saturation); without them the log is exactly the clean one.

Randomness: each period draws from its own generator,
``SeedSequence(entropy, spawn_key=(temperature index, velocity index, repetition))``, so the
same seed gives bit-identical samples however the campaign is chunked, and global random state
is never touched.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace

import numpy as np

from ..errors import ConfigError
from ..samples import RawLog
from . import faults as _faults
from .joint import Scenario

__all__ = ["CHUNKS", "SeedLike", "root_entropy", "simulate", "simulate_log"]

#: What ``seed`` accepts: an int, a Generator, a SeedSequence or None (fresh entropy).
SeedLike = int | np.random.Generator | np.random.SeedSequence | None

#: How :func:`simulate` may cut the campaign into logs.
CHUNKS = ("period", "setpoint", "experiment")

_COLUMNS = ("time", "position", "velocity", "current", "temperature")


def root_entropy(seed: SeedLike) -> int:
    """The integer entropy every period's generator derives from.

    ``seed`` is an int, a :class:`numpy.random.SeedSequence`, a :class:`numpy.random.Generator`
    (one integer is drawn from it) or None (fresh entropy from the operating system).
    """
    if isinstance(seed, np.random.Generator):
        return int(seed.integers(0, 2**63))
    if isinstance(seed, np.random.SeedSequence):
        entropy = seed.entropy
    elif seed is None:
        entropy = np.random.SeedSequence().entropy
    elif isinstance(seed, int | np.integer) and not isinstance(seed, bool) and seed >= 0:
        entropy = int(seed)
    else:
        raise ConfigError(f"seed must be a non-negative int, a Generator or None, got {seed!r}")
    if not isinstance(entropy, int):
        raise ConfigError("seed: only integer SeedSequence entropy is supported")
    return entropy


def _period(
    scenario: Scenario, it: int, iv: int, rep: int, k0: int, entropy: int, out: dict, at: int
) -> int:
    """Simulate one period into ``out[...][at:at+n]``; return n (the samples the design
    records: fewer than the period's with ``coverage="split"``)."""
    design, joint, noise = scenario.design, scenario.joint, scenario.noise
    faults = scenario.faults if scenario.faults is not None and scenario.faults.active else None
    temperature = float(design.temperatures[it])
    traverse = design.traverse(design.velocities[iv])
    rng = np.random.default_rng(np.random.SeedSequence(entropy, spawn_key=(it, iv, rep)))
    if faults is None:
        n = traverse.n_period
        k = np.arange(n)
        prof = traverse.profile(k / design.sample_rate)
    else:
        # faults draw from their own stream: the clean draws below stay as they were
        frng = np.random.default_rng(np.random.SeedSequence(entropy, spawn_key=(it, iv, rep, 1)))
        faulty = _faults.period(faults, traverse, frng)
        prof = faulty.profile
        n = prof.position.size
        k = np.arange(n)

    # draws in a fixed order: pass offsets, current noise, spikes, velocity, temperature
    offsets = rng.normal(0.0, noise.pass_offset_std, 2)
    tau = joint.motor_torque(
        prof.position, prof.velocity, prof.acceleration, temperature, offsets[prof.pass_index]
    )
    if faults is not None:
        tau = tau + faulty.extra_torque + _holding(scenario, faulty, prof, temperature, frng)
    current = tau / joint.torque_constant + rng.normal(0.0, noise.current_std, n)
    n_spikes = rng.binomial(n, noise.spike_rate)
    where = rng.integers(0, n, n_spikes)
    size = rng.uniform(noise.spike_min, noise.spike_max, n_spikes)
    sign = np.where(rng.random(n_spikes) < 0.5, -1.0, 1.0)
    current[where] += sign * size
    if faults is not None:
        current += _faults.bursts(faults, n, frng)
    if noise.current_lsb > 0:
        current = np.round(current / noise.current_lsb) * noise.current_lsb
    if faults is not None and faults.current_range > 0:
        current = np.clip(current, -faults.current_range, faults.current_range)
    velocity_std = noise.velocity_rel_std * np.abs(prof.velocity) + noise.velocity_abs_std
    velocity = prof.velocity + velocity_std * rng.standard_normal(n)
    if faults is not None and faults.rest_time > 0:
        # at rest the velocity estimate is float residue, not sensor noise
        velocity = np.where(
            faulty.rest, _faults.rest_velocity(faults, faulty.rest_id, frng), velocity
        )
    position = prof.position
    if noise.position_lsb > 0:
        position = np.round(position / noise.position_lsb) * noise.position_lsb
    temp = temperature + rng.normal(0.0, noise.temperature_std, n)

    keep = design.recorded(prof.position, prof.velocity)  # all, unless coverage="split"
    n = int(keep.sum())
    s = np.s_[at : at + n]
    out["time"][s] = ((k0 + k) / design.sample_rate)[keep]
    out["position"][s] = position[keep]
    out["velocity"][s] = velocity[keep]
    out["current"][s] = current[keep]
    out["temperature"][s] = temp[keep]
    return n


def _holding(scenario: Scenario, faulty, prof, temperature: float, rng) -> np.ndarray:
    """Torque [N m] the joint holds at rest (rest-time fault): a random fraction in (-1, 1),
    one per rest stretch, of the break-away friction; zero while moving. The clean model
    (eq. 6) gives 0 friction at rest, only gravity."""
    if scenario.faults.rest_time <= 0:
        return np.zeros(prof.position.size)
    load = scenario.joint.gravity(prof.position)
    breakaway = np.abs(scenario.joint.law(np.full(load.shape, 1e-12), load, temperature))
    share = rng.uniform(-1.0, 1.0, 2)[np.maximum(faulty.rest_id, 0)]
    return np.where(faulty.rest, share * breakaway, 0.0)


def simulate(
    scenario: Scenario, *, seed: SeedLike = None, chunk: str = "setpoint"
) -> Iterator[RawLog]:
    """Simulate the scenario's campaign, yielding one :class:`RawLog` per chunk.

    Parameters
    ----------
    scenario : what to run (see :func:`fricid.sim.preset`).
    seed : int, Generator, SeedSequence or None; same seed, bit-identical logs.
    chunk : "period" (one forward plus backward traverse), "setpoint" (all repetitions of one
        velocity at one temperature; the default) or "experiment" (one temperature; about
        3.5 million samples, 140 MB, for the full ``paper1`` design).

    Yields
    ------
    RawLog with the current column (no torque) and ``torque_constant`` K, time continuous over
    the campaign (experiments separated by ``design.experiment_gap``). ``meta`` names the
    scenario, the seed entropy and the chunk's temperature and velocity indices.
    """
    if chunk not in CHUNKS:
        raise ConfigError(f"simulate: unknown chunk '{chunk}'; use one of: {', '.join(CHUNKS)}")
    entropy = root_entropy(seed)
    design = scenario.design
    n_t, n_v, _ = design.shape
    reps = design.repetitions
    per_period = [scenario.period_length(iv) for iv in range(n_v)]
    gap = round(design.experiment_gap * design.sample_rate)

    def plan() -> Iterator[list[tuple[int, int, int, int]]]:
        k0 = 0
        for it in range(n_t):
            experiment = []
            for iv in range(n_v):
                setpoint = []
                for rep in range(reps):
                    setpoint.append((it, iv, rep, k0))
                    k0 += per_period[iv]
                if chunk == "setpoint":
                    yield setpoint
                elif chunk == "period":
                    yield from ([p] for p in setpoint)
                else:
                    experiment.extend(setpoint)
            if chunk == "experiment":
                yield experiment
            k0 += gap

    source = f"sim:{scenario.name}/{scenario.size}"
    for periods in plan():
        total = sum(per_period[iv] for _, iv, _, _ in periods)
        out = {name: np.empty(total) for name in _COLUMNS}
        at = 0
        for it, iv, rep, k0 in periods:
            at += _period(scenario, it, iv, rep, k0, entropy, out, at)
        out = {name: column[:at] for name, column in out.items()}
        it0, iv0 = periods[0][0], periods[0][1]
        yield RawLog(
            time=out["time"],
            position=out["position"],
            velocity=out["velocity"],
            temperature=out["temperature"],
            current=out["current"],
            torque_constant=scenario.joint.torque_constant,
            joint=scenario.name,
            source=source,
            meta={
                "scenario": scenario.name,
                "size": scenario.size,
                "seed_entropy": entropy,
                "temperature_index": it0,
                "velocity_index": None if chunk == "experiment" else iv0,
                "repetition": periods[0][2] if chunk == "period" else None,
            },
        )


def simulate_log(scenario: Scenario, *, seed: SeedLike = None) -> RawLog:
    """The whole campaign as one :class:`RawLog` (for the ``reduced`` and ``quick`` sizes; the
    full ``paper1`` campaign is tens of millions of samples: stream :func:`simulate` instead)."""
    entropy = root_entropy(seed)
    log = RawLog.concatenate(list(simulate(scenario, seed=entropy, chunk="experiment")))
    meta = {"scenario": scenario.name, "size": scenario.size, "seed_entropy": entropy}
    return replace(log, meta=meta)
