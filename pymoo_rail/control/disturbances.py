"""Disturbed trains for controller studies: load, adhesion, speed-measurement noise, traction lag.

A :class:`Disturbance` is one scenario: the train is heavier or lighter than the one the reference
curve was computed for (``mass_factor``), its usable traction and braking forces are scaled by the
rail's adhesion (``adhesion_factor``; the braking envelope is rebuilt with the reduced brakes, as an
ATP would with a known adhesion), its speed sensor adds Gaussian noise at each control instant
(``speed_noise_kmh``, standard deviation) and its traction and brake equipment follows the command
through a first-order lag (``traction_lag_s``). :func:`draw_disturbances` draws scenarios from
given ranges with one seeded generator, so a training set and a held-out set are reproducible.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.control.controllers import Controller
from pymoo_rail.control.tracking import DEFAULT_CONTROL_PERIOD_S, Tracker
from pymoo_rail.model import Case
from pymoo_rail.sim import Trajectory
from pymoo_rail.sim.physics import KernelModel, braking_envelope

# Ranges of the study (issue text: mass +-15 %); the others are reconstructed, typical values.
DEFAULT_RANGES = {"mass_factor": (0.85, 1.15), "adhesion_factor": (0.8, 1.0), "speed_noise_kmh": (0.0, 0.5),
                  "traction_lag_s": (0.0, 0.6)}
_N_NOISE = 4096  # control instants of noise per scenario (cycled beyond)


@dataclass(frozen=True)
class Disturbance:
    """One disturbed scenario (see the module docstring); the defaults are the nominal train."""

    mass_factor: float = 1.0
    adhesion_factor: float = 1.0
    speed_noise_kmh: float = 0.0
    traction_lag_s: float = 0.0
    noise_seed: int = 0

    def __post_init__(self) -> None:
        for name in ("mass_factor", "adhesion_factor"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"{name} = {value!r} must be a positive number")
        for name in ("speed_noise_kmh", "traction_lag_s"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ValueError(f"{name} = {value!r} must be a number >= 0")

    def case(self, case: Case) -> Case:
        """The case with the disturbed train mass."""
        return replace(case, train=replace(case.train, mass_t=case.train.mass_t * self.mass_factor))

    def noise_ms(self) -> np.ndarray:
        """Measurement noise (m/s) at successive control instants."""
        if self.speed_noise_kmh == 0.0:
            return np.zeros(0)
        return np.random.default_rng(self.noise_seed).normal(0.0, self.speed_noise_kmh / KMH_PER_MS, _N_NOISE)


def draw_disturbances(n: int, seed: int, ranges: dict | None = None) -> list[Disturbance]:
    """``n`` scenarios with every factor uniform in its range (``DEFAULT_RANGES``), reproducible by ``seed``."""
    if not isinstance(n, (int, np.integer)) or n < 1:
        raise ValueError(f"n = {n!r} must be a positive integer")
    ranges = {**DEFAULT_RANGES, **(ranges or {})}
    unknown = set(ranges) - set(DEFAULT_RANGES)
    if unknown:
        raise ValueError(f"ranges has unknown keys {sorted(unknown)} (known: {sorted(DEFAULT_RANGES)})")
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        values = {k: float(rng.uniform(lo, hi)) for k, (lo, hi) in ranges.items()}
        out.append(Disturbance(**values, noise_seed=int(rng.integers(2**31))))
    return out


def disturbed_tracker(case: Case, controller: Controller, disturbance: Disturbance,
                      control_period_s: float = DEFAULT_CONTROL_PERIOD_S, dx_m: float | None = None) -> Tracker:
    """A tracker of the disturbed train: its mass, and its traction and braking force caps scaled by adhesion."""
    tracker = Tracker(disturbance.case(case), controller, control_period_s, dx_m)
    if disturbance.adhesion_factor != 1.0:
        tracker.simulator.model = adhesion_limited(tracker.simulator.model, disturbance.adhesion_factor)
    return tracker


def adhesion_limited(model: KernelModel, adhesion_factor: float) -> KernelModel:
    """The kernels' model with traction and braking force caps at ``adhesion_factor`` of their curves' peaks.

    The braking envelope is rebuilt with the reduced brakes, as an ATP does with a known adhesion.
    """
    f = float(adhesion_factor)
    if f == 1.0:
        return model
    m = model._replace(traction_max_n=min(model.traction_max_n, f * _peak_force(model, traction=True)),
                       brake_max_n=min(model.brake_max_n, f * _peak_force(model, traction=False)))
    return m._replace(envelope_ms=braking_envelope(m))


def _peak_force(model, traction: bool) -> float:
    """Largest force of a curve over 0-120 km/h (the level the adhesion factor scales)."""
    from pymoo_rail.sim.physics import curve_force

    v = np.linspace(0.0, 120 / KMH_PER_MS, 241)
    if traction:
        return max(curve_force(x, model.traction_breaks_ms, model.traction_coefs, model.traction_max_n,
                               model.traction_max_w) for x in v)
    return max(curve_force(x, model.brake_breaks_ms, model.brake_coefs, model.brake_max_n, model.brake_max_w)
               for x in v)


def track_disturbed(case: Case, reference: Trajectory, controller: Controller, disturbance: Disturbance,
                    control_period_s: float = DEFAULT_CONTROL_PERIOD_S, dx_m: float | None = None) -> Trajectory:
    """The disturbed train tracking ``reference`` under ``controller``."""
    tracker = disturbed_tracker(case, controller, disturbance, control_period_s, dx_m)
    return tracker.run(reference, disturbance.noise_ms(), disturbance.traction_lag_s)
