"""What a train learns about itself on the way: its running resistance, from measured speed and applied force.

The planner of a real ATO knows the line (gradients, curves), the train's mass (weighed at
departure) and the force it applies (from the drive's current), but not the running resistance
of the day (wind, bearings, rolling stock in another state than the one measured). The work
balance from departure (at standstill, position 0) to a measured instant ``j`` is

    m_eff v_j^2 / 2 = W_F(x_j) - W_L(x_j) - f * sum_i W0(v_i) dx_i

with ``W_F`` the work of the applied traction and braking force, ``W_L`` that of the line
(gradients, curves), ``W0`` the case's Davis resistance and ``f`` the unknown scale factor. With
``y_j = W_F - W_L - m_eff v_j^2 / 2`` and ``phi_j = sum W0 dx`` this is ``y_j = f phi_j + e_j``,
where ``e_j ~ m_eff v_j dv_j`` comes from the speed sensor's noise ``dv_j`` (independent between
instants). :func:`estimate_resistance` is the weighted least-squares estimate of ``f`` over every
instant so far with a Gaussian prior around 1 (the recursive least-squares estimate in batch form:
the same number, recomputed from the whole run at each decision). Only the endpoint speed of each
balance enters it, so the sensor noise is not differentiated.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model.errors import FieldError, check_number
from pymoo_rail.sim.physics import KernelModel

# The sensor's noise is taken at least this large (m/s), so that a noise-free sensor gets finite weights
MIN_SPEED_SD_MS = 1e-3
# Below this speed (m/s) the noise term m v dv is taken at this speed (a standing train's reading is not exact)
MIN_WEIGHT_SPEED_MS = 1.0


@dataclass(frozen=True)
class RunMeasurements:
    """What the train measured from departure (standstill at position 0) up to now, at the sensor's instants.

    Attributes
    ----------
    time_s : (n,) array
        Instants on the plan's clock (s), increasing.
    position_m : (n,) array
        Positions (m) at those instants (the odometer).
    speed_ms : (n,) array
        Measured speeds (m/s), with the sensor's noise.
    force_work_j : (n,) array
        Work of the applied traction and braking force from departure to each instant (J).
    """

    time_s: np.ndarray
    position_m: np.ndarray
    speed_ms: np.ndarray
    force_work_j: np.ndarray

    def __post_init__(self) -> None:
        n = np.shape(self.time_s)[0] if np.ndim(self.time_s) == 1 else -1
        for name in ("time_s", "position_m", "speed_ms", "force_work_j"):
            value = np.asarray(getattr(self, name), dtype=float)
            if value.ndim != 1 or value.shape[0] != n:
                raise FieldError(f"measured.{name}", getattr(self, name), "must be a 1-D array as long as time_s")
            bad = np.flatnonzero(~np.isfinite(value))
            if bad.size:
                raise FieldError(f"measured.{name}[{int(bad[0])}]", float(value[bad[0]]), "must be finite")


def estimate_resistance(model: KernelModel, measured: RunMeasurements, speed_sd_ms: float,
                        prior_sd: float = 0.1) -> tuple[float, float]:
    """The running-resistance scale factor of the real train and its standard deviation.

    Parameters
    ----------
    model : KernelModel
        The planner's model of the line and train (its own mass, the case's Davis resistance).
    measured : RunMeasurements
        The run so far.
    speed_sd_ms : float
        Standard deviation of the speed sensor (m/s).
    prior_sd : float
        Standard deviation of the prior around 1 (the resistance as measured for the case).

    Returns
    -------
    (factor, sd)
        The posterior mean of ``f`` (see the module docstring) and its standard deviation.
    """
    sd = max(check_number("speed_sd_ms", speed_sd_ms, nonneg=True, error=FieldError), MIN_SPEED_SD_MS)
    check_number("prior_sd", prior_sd, positive=True, error=FieldError)
    x = np.asarray(measured.position_m, dtype=float)
    v = np.maximum(np.asarray(measured.speed_ms, dtype=float), 0.0)
    if x.shape[0] < 2:
        return 1.0, float(prior_sd)
    grid = np.asarray(model.position_m, dtype=float)
    line_work = np.concatenate([[0.0], np.cumsum(np.asarray(model.line_force_n) * np.diff(grid))])
    v_mid = 0.5 * (v[1:] + v[:-1])
    w0 = model.davis_a_n + (model.davis_b_nsm + model.davis_c_ns2m2 * v_mid) * v_mid
    phi = np.concatenate([[0.0], np.cumsum(w0 * np.diff(x))])
    y = np.asarray(measured.force_work_j) - np.interp(x, grid, line_work) - 0.5 * model.effective_mass_kg * v * v
    weight = 1.0 / (model.effective_mass_kg * sd * np.maximum(v, MIN_WEIGHT_SPEED_MS)) ** 2
    precision = float(np.sum(weight * phi * phi)) + 1.0 / prior_sd ** 2
    factor = (float(np.sum(weight * phi * y)) + 1.0 / prior_sd ** 2) / precision
    return factor, 1.0 / math.sqrt(precision)


@dataclass
class ResistanceEstimator:
    """The running-resistance factor a re-planning controller hands its planner, estimated on the way.

    Parameters
    ----------
    speed_noise_kmh : float
        The speed sensor's standard deviation the estimator assumes (km/h; the study's worlds draw
        0 to 0.5).
    prior_sd : float
        Standard deviation of the prior of the factor around 1.
    step_factor : float
        The factor in use moves in steps of this size, and only once the estimate is more than a
        step away from it: every new factor is a new planner line (transition tables and sweeps).

    Attributes
    ----------
    factor : float
        The factor in use (1 until the estimate moves).
    history : list of (time_s, estimate, sd)
        Each update's estimate.
    """

    speed_noise_kmh: float = 0.5
    prior_sd: float = 0.1
    step_factor: float = 0.02
    factor: float = 1.0
    history: list = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        check_number("speed_noise_kmh", self.speed_noise_kmh, nonneg=True, error=FieldError)
        check_number("prior_sd", self.prior_sd, positive=True, error=FieldError)
        check_number("step_factor", self.step_factor, positive=True, error=FieldError)
        check_number("factor", self.factor, positive=True, error=FieldError)
        self.history = [] if self.history is None else self.history

    def update(self, model: KernelModel, measured: RunMeasurements) -> float:
        """Estimate from the run so far (:func:`estimate_resistance`); returns the factor in use."""
        estimate, sd = estimate_resistance(model, measured, self.speed_noise_kmh / KMH_PER_MS, self.prior_sd)
        self.history.append((float(measured.time_s[-1]), estimate, sd))
        if abs(estimate - self.factor) > self.step_factor and estimate > 0.0:
            self.factor = round(estimate / self.step_factor) * self.step_factor
        return self.factor
