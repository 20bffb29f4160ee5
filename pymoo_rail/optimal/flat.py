"""The closed-form optimum on level track, from Pontryagin's maximum principle.

On level track without binding speed limits the minimum-energy run for a given time is
maximum traction to a hold speed ``V``, holding ``V``, coasting down to ``W``, maximum braking
(Liu (2019) section 2.2.5; Howlett and Pudney). With time priced at ``lambda`` (plus the auxiliary
power ``P_aux``, which costs exactly like time), traction efficiency ``eta`` and regenerative
braking efficiency ``eta_b``, the Hamiltonian over distance is
``H = f+/eta - eta_b f- + (lambda + P_aux)/v + p (f+ - f- - R(v)) / (m_eff v)``:

- on the hold arc the traction coefficient vanishes, ``p = -m_eff V / eta``, and ``dp/dx = 0`` gives
  ``lambda + P_aux = V^2 R'(V) / eta``;
- braking begins where the braking coefficient vanishes, ``p = -eta_b m_eff W``; ``H`` is constant
  along the run (level track), so ``(lambda + P_aux) / W + eta_b R(W) = R(V) / eta + (lambda + P_aux) / V``
  (without regeneration, ``eta_b = 0``, the classical ``lambda / W = R(V) / eta + lambda / V``).

The run starts at the case's initial speed and brakes down to its final speed. The phases are
integrated by quadrature of the equations of motion, independently of the simulator and of the
DP; ``lambda`` is then found so that the phases add up to the requested time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from scipy.integrate import quad
from scipy.optimize import brentq

from pymoo_rail.constants import J_PER_KWH, KMH_PER_MS
from pymoo_rail.model import GRAVITY_MS2, Case


@dataclass(frozen=True)
class FlatTrackOptimum:
    """The four phases of the optimum on level track (SI units, energies in kWh)."""

    lambda_w: float
    hold_speed_ms: float
    brake_speed_ms: float
    traction_end_m: float
    coast_start_m: float
    brake_start_m: float
    running_time_s: float
    energy_kwh: float


def _check_flat(case: Case, level: bool = True) -> float:
    """The line's one gradient (per mille); raises unless the closed form applies."""
    line, train = case.line, case.train
    grades = {g[2] for g in line.gradients}
    if len(grades) != 1 or (level and grades != {0.0}) or line.curves or line.tunnels or line.neutral_sections:
        raise ValueError(f"case '{case.name}': the closed form needs {'level track' if level else 'one gradient'} "
                         "without curves, tunnels or neutral sections")
    if train.regen_efficiency != 0.0 and (train.regen_min_speed_kmh != 0.0 or train.regen_max_force_kn is not None
                                          or train.regen_max_power_kw is not None):
        raise ValueError(f"case '{case.name}': the closed form with regeneration assumes that all braking "
                         "regenerates (no regen caps, no cut-off speed)")
    if train.traction_efficiency_map is not None or train.regen_efficiency_map is not None:
        raise ValueError(f"case '{case.name}': the closed form assumes constant efficiencies, not an efficiency map")
    return grades.pop()


@dataclass(frozen=True)
class _FlatModel:
    """The case's train on its one gradient, as the closed form needs it (SI units)."""

    case: Case
    m: float  # effective mass (kg)
    a: float  # Davis a plus the gradient force (N)
    b: float
    c: float
    limit: float  # lowest limit (m/s)

    @classmethod
    def of(cls, case: Case) -> _FlatModel:
        permille = _check_flat(case, level=False)
        train = case.train
        a, b, c = train.resistance.coefficients_si(train.mass_kg)
        a += train.mass_kg * GRAVITY_MS2 * permille / 1000.0  # the gradient force, independent of the speed
        if a <= 0.0:
            raise ValueError(f"case '{case.name}': on {permille:g} per mille coasting accelerates at low speed; the "
                             "closed form needs R(v) + G > 0")
        limit = min(min(row[2] for row in case.line.speed_limits), train.max_speed_kmh) / KMH_PER_MS
        return cls(case, train.effective_mass_kg, a, b, c, limit)

    def resist(self, v):
        return self.a + self.b * v + self.c * v * v

    def traction(self, v):
        train = self.case.train
        f = float(train.traction.force_kn(v * KMH_PER_MS)[0]) * 1000.0
        a_max = train.max_accel_ms2 if train.max_accel_ms2 is not None else math.inf
        return min(f, self.m * a_max + self.resist(v))

    def braking(self, v):
        train = self.case.train
        f = float(train.braking.force_kn(v * KMH_PER_MS)[0]) * 1000.0
        d_max = train.max_decel_ms2 if train.max_decel_ms2 is not None else math.inf
        return min(f, self.m * d_max - self.resist(v))

    def brake_speed(self, hold, price):
        """``W`` from the constancy of the Hamiltonian: ``price / W + eta_b R(W) = R(V) / eta + price / V``."""
        eta, eta_b = self.case.train.traction_efficiency, self.case.train.regen_efficiency
        # (price / W + eta_b R(W)) falls from +inf to below its value at V on (0, V]
        rhs = self.resist(hold) / eta + price / hold
        return brentq(lambda w: price / w + eta_b * self.resist(w) - rhs, 1e-9 * hold, hold, xtol=1e-14, rtol=1e-15)

    def phases(self, lam):
        """(hold speed, brake speed, traction length, hold length, coast length, time s, energy J) at ``lam``."""
        train, m, resist, traction, braking = self.case.train, self.m, self.resist, self.traction, self.braking
        eta, eta_b, aux = train.traction_efficiency, train.regen_efficiency, train.aux_power_kw * 1000.0
        v_start, v_end = self.case.initial_speed_ms, self.case.final_speed_ms
        price = lam + aux
        # hold speed from lambda + P_aux = V^2 R'(V) / eta (increasing in V)
        hold = brentq(lambda v: v * v * (self.b + 2 * self.c * v) / eta - price, 1e-9, 10 * self.limit)
        brake = self.brake_speed(hold, price)
        opts = {"limit": 200, "epsabs": 0.0, "epsrel": 1e-11}
        s_a = quad(lambda v: m * v / (traction(v) - resist(v)), v_start, hold, **opts)[0]
        t_a = quad(lambda v: m / (traction(v) - resist(v)), v_start, hold, **opts)[0]
        e_a = quad(lambda v: traction(v) * m * v / (traction(v) - resist(v)), v_start, hold, **opts)[0] / eta
        s_c = quad(lambda v: m * v / resist(v), brake, hold, **opts)[0]
        t_c = quad(lambda v: m / resist(v), brake, hold, **opts)[0]
        s_b = quad(lambda v: m * v / (braking(v) + resist(v)), v_end, brake, **opts)[0]
        t_b = quad(lambda v: m / (braking(v) + resist(v)), v_end, brake, **opts)[0]
        e_b = quad(lambda v: braking(v) * m * v / (braking(v) + resist(v)), v_end, brake, **opts)[0] * eta_b
        s_h = self.case.line.length_m - s_a - s_c - s_b
        t = t_a + s_h / hold + t_c + t_b
        e = e_a + resist(hold) * s_h / eta - e_b + aux * t
        return hold, brake, s_a, s_h, s_c, t, e


def flat_track_optimum(case: Case, running_time_s: float) -> FlatTrackOptimum:
    """The optimal traction-hold-coast-brake run of a level (or constant-gradient) case taking ``running_time_s``.

    On a single constant gradient the gradient force ``G = m g i`` adds to the resistance: it
    does not depend on the speed, so the hold speed ``V`` is the level one (``psi(V) = v^2 R'(v)``),
    and the switching conditions hold with ``R + G``. Needs ``R(v) + G > 0`` (coasting decelerates
    at every speed up to the hold speed; otherwise holding is by braking at ``W``, another structure).

    The hold speed stays below every speed limit (``lambda`` is searched only up to the limit); the
    train's acceleration and deceleration caps, regenerative braking (all braking electric), the
    auxiliary power and the boundary speeds are honoured. Raises ``ValueError`` when the case is not
    level, or when no hold speed fits the time.
    """
    model = _FlatModel.of(case)
    eta, aux = case.train.traction_efficiency, case.train.aux_power_kw * 1000.0
    limit = model.limit

    def time_gap(log_lam):
        return model.phases(math.exp(log_lam))[5] - running_time_s

    # lambda from a crawl (1 W) up to the hold speed at the lowest limit, and a hold length >= 0
    lo = math.log(1.0)
    hi = math.log(max(limit * limit * (model.b + 2 * model.c * limit) / eta - aux, 2.0))
    if model.phases(math.exp(hi))[3] < 0.0:
        hi = brentq(lambda x: model.phases(math.exp(x))[3], lo, hi, xtol=1e-12)
    if not time_gap(lo) > 0.0 > time_gap(hi):
        raise ValueError(f"running_time_s = {running_time_s}: outside the times a hold phase can give "
                         f"({model.phases(math.exp(hi))[5]:.2f} .. {model.phases(math.exp(lo))[5]:.2f} s)")
    lam = math.exp(brentq(time_gap, lo, hi, xtol=1e-13, rtol=1e-13))
    hold, brake, s_a, s_h, s_c, t, e = model.phases(lam)
    return FlatTrackOptimum(lambda_w=lam, hold_speed_ms=hold, brake_speed_ms=brake, traction_end_m=s_a,
                            coast_start_m=s_a + s_h, brake_start_m=s_a + s_h + s_c, running_time_s=t,
                            energy_kwh=e / J_PER_KWH)


def no_resistance_optimum(case: Case, running_time_s: float) -> tuple[float, float]:
    """Level track, no resistance, constant forces, no regeneration: accelerate to V, coast, brake.

    Returns ``(V m/s, energy kWh)`` with ``T = V / a + V / d + (L - V^2 / 2a - V^2 / 2d) / V``.
    """
    _check_flat(case)
    if case.train.regen_efficiency or case.train.aux_power_kw or case.initial_speed_ms or case.final_speed_ms:
        raise ValueError(f"case '{case.name}': this closed form assumes no regeneration, no auxiliary power "
                         "and a run from rest to rest")
    train = case.train
    m = train.effective_mass_kg
    acc = float(train.traction.force_kn(0.0)[0]) * 1000.0 / m
    dec = float(train.braking.force_kn(0.0)[0]) * 1000.0 / m
    if train.max_accel_ms2 is not None:
        acc = min(acc, train.max_accel_ms2)
    if train.max_decel_ms2 is not None:
        dec = min(dec, train.max_decel_ms2)
    k = 0.5 / acc + 0.5 / dec
    # T V = k V^2 + L  ->  k V^2 - T V + L = 0, smaller root
    disc = running_time_s ** 2 - 4 * k * case.line.length_m
    if disc < 0:
        raise ValueError(f"running_time_s = {running_time_s}: below the minimum {math.sqrt(4 * k * case.line.length_m):.2f} s")
    v = (running_time_s - math.sqrt(disc)) / (2 * k)
    return v, 0.5 * m * v * v / train.traction_efficiency / J_PER_KWH

