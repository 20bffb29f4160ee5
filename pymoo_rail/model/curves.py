"""Traction and braking limit curves: piecewise polynomials, tables, or force + power caps."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model.errors import CaseError, check_number



@dataclass(frozen=True)
class ForceCurve:
    """Maximum force as a function of speed, in the case file's railway units (kN, km/h).

    Exactly one of ``segments``, ``table`` or ``max_force_kn`` describes the curve; ``max_power_kw``
    may be added to any of them as a further cap ``F <= P / v``.

    Parameters
    ----------
    segments : tuple of (v_max_kmh, coefficients)
        Piecewise polynomials in v (km/h) giving kN, coefficients from low to high order, ordered
        by speed. Segment k applies up to ``v_max_kmh``; the last one also beyond it.
    table : tuple of (v_kmh, force_kn)
        Points interpolated linearly (Liu (2019) eq. 2-2), speeds strictly increasing from 0.
    max_force_kn : float
        A constant force cap.
    max_power_kw : float
        A power cap (hyperbolic part of the curve).
    """

    segments: tuple[tuple[float, tuple[float, ...]], ...] | None = None
    table: tuple[tuple[float, float], ...] | None = None
    max_force_kn: float | None = None
    max_power_kw: float | None = None

    def __post_init__(self) -> None:
        forms = [f for f in ("segments", "table", "max_force_kn") if getattr(self, f) is not None]
        if len(forms) != 1:
            raise CaseError("segments|table|max_force_kn", forms,
                            "exactly one form of the force curve must be given")
        if self.segments is not None:
            if len(self.segments) == 0:
                raise CaseError("segments", [], "needs at least one segment {v_max_kmh = ..., poly = [...]}")
            last = 0.0
            for k, (v_max, poly) in enumerate(self.segments):
                v_max = check_number(f"segments[{k}].v_max_kmh", v_max)
                if not v_max > last:
                    raise CaseError(f"segments[{k}].v_max_kmh", v_max, "segment speeds must be > 0 and strictly increase")
                if len(poly) == 0:
                    raise CaseError(f"segments[{k}].poly", list(poly), "needs at least one coefficient")
                for j, c in enumerate(poly):
                    check_number(f"segments[{k}].poly[{j}]", c)
                last = v_max
        if self.table is not None:
            if len(self.table) == 0:
                raise CaseError("table", [], "needs at least one point [v_kmh, force_kn]")
            for k, row in enumerate(self.table):
                if len(row) != 2:
                    raise CaseError(f"table[{k}]", list(row), "needs 2 numbers [v_kmh, force_kn]")
                check_number(f"table[{k}][0]", row[0], nonneg=True)
                check_number(f"table[{k}][1]", row[1], nonneg=True)
            if self.table[0][0] != 0.0:
                raise CaseError("table[0]", list(self.table[0]), "the first point must be at 0 km/h")
            for k in range(1, len(self.table)):
                if not self.table[k][0] > self.table[k - 1][0]:
                    raise CaseError(f"table[{k}]", list(self.table[k]), "speeds must strictly increase")
        check_number("max_force_kn", self.max_force_kn, positive=True, optional=True)
        check_number("max_power_kw", self.max_power_kw, positive=True, optional=True)

    def check_nonnegative(self, field: str, max_speed_kmh: float) -> None:
        """Raise :class:`CaseError` if a polynomial segment is negative anywhere from 0 to
        ``max_speed_kmh`` (a negative force limit would be clipped to 0: another train)."""
        if self.segments is None:
            return  # tables and caps are checked >= 0 point by point
        lower = 0.0
        for k, (v_max, poly) in enumerate(self.segments):
            # the speeds the train uses: the last segment also applies beyond its v_max
            upper = max_speed_kmh if k == len(self.segments) - 1 else min(v_max, max_speed_kmh)
            if upper > lower:
                speed, value = _polynomial_minimum(poly, lower, upper)
                if value < -1e-9:
                    raise CaseError(f"{field}.segments[{k}].poly", list(poly),
                                    f"gives {value:.6g} kN at {speed:.6g} km/h: a force limit must be >= 0 over "
                                    f"the segment's speeds [{lower:g}, {upper:g}] km/h")
            lower = v_max

    def piecewise_si(self) -> tuple[np.ndarray, np.ndarray, float, float]:
        """The curve in SI units for the kernels.

        Returns
        -------
        breaks_ms : (n,) upper speed of each segment in m/s (the last is +inf)
        coefs : (n, d) polynomial coefficients in N with v in m/s, low to high order
        max_force_n, max_power_w : caps (+inf when absent)
        """
        if self.segments is not None:
            pieces = [(v, list(p)) for v, p in self.segments]
        elif self.table is not None:
            pieces = []
            pts = self.table
            for k in range(len(pts) - 1):
                (v0, f0), (v1, f1) = pts[k], pts[k + 1]
                slope = (f1 - f0) / (v1 - v0)
                pieces.append((v1, [f0 - slope * v0, slope]))
            pieces.append((math.inf, [pts[-1][1]]))
        else:
            pieces = [(math.inf, [self.max_force_kn])]
        degree = max(len(p) for _, p in pieces)
        breaks = np.empty(len(pieces))
        coefs = np.zeros((len(pieces), degree))
        for k, (v_max, poly) in enumerate(pieces):
            breaks[k] = v_max / KMH_PER_MS
            for j, c in enumerate(poly):
                coefs[k, j] = c * 1000.0 * KMH_PER_MS ** j  # kN(v km/h) -> N(v m/s)
        breaks[-1] = math.inf
        f_cap = self.max_force_kn * 1000.0 if self.max_force_kn is not None else math.inf
        p_cap = self.max_power_kw * 1000.0 if self.max_power_kw is not None else math.inf
        return breaks, coefs, f_cap, p_cap

    def force_kn(self, speed_kmh: np.ndarray | float) -> np.ndarray:
        """Evaluate the curve in railway units (plain numpy; the kernels use ``piecewise_si``)."""
        v = np.atleast_1d(np.asarray(speed_kmh, dtype=float))
        if self.segments is not None:
            out = np.empty_like(v)
            uppers = np.array([s[0] for s in self.segments])
            idx = np.minimum(np.searchsorted(uppers, v, side="left"), len(uppers) - 1)
            for k, (_, poly) in enumerate(self.segments):
                mask = idx == k
                out[mask] = np.polynomial.polynomial.polyval(v[mask], poly)
        elif self.table is not None:
            vs, fs = zip(*self.table)
            out = np.interp(v, vs, fs)
        else:
            out = np.full_like(v, self.max_force_kn)
        if self.max_power_kw is not None:
            with np.errstate(divide="ignore"):
                out = np.minimum(out, np.where(v > 0, self.max_power_kw * KMH_PER_MS / np.maximum(v, 1e-300), np.inf))
        return np.maximum(out, 0.0)


def _polynomial_minimum(poly: tuple[float, ...], lower: float, upper: float) -> tuple[float, float]:
    """(speed, value) of the smallest value of a polynomial on [lower, upper] (ends and stationary points)."""
    candidates = [lower, upper]
    if len(poly) > 2:
        derivative = np.polynomial.polynomial.polyder(np.asarray(poly, dtype=float))
        for root in np.polynomial.polynomial.polyroots(derivative):
            if abs(root.imag) < 1e-9 and lower < root.real < upper:
                candidates.append(float(root.real))
    values = np.polynomial.polynomial.polyval(np.asarray(candidates), np.asarray(poly, dtype=float))
    k = int(np.argmin(values))
    return candidates[k], float(values[k])


@dataclass(frozen=True)
class DavisResistance:
    """Basic running resistance ``W0 = a + b v + c v^2``.

    ``unit`` says whether W0 is a total force in kN or a specific resistance in N/kN (per unit of
    train weight); ``speed_unit`` says whether v is in km/h or m/s. Both are required: guessing
    them silently is the commonest error in published train models.
    """

    a: float
    b: float
    c: float
    unit: str
    speed_unit: str

    def __post_init__(self) -> None:
        for name in ("a", "b", "c"):
            check_number(f"train.resistance.{name}", getattr(self, name), nonneg=True)
        if self.unit not in ("kN", "N/kN"):
            raise CaseError("train.resistance.unit", self.unit, "must be 'kN' or 'N/kN'")
        if self.speed_unit not in ("kmh", "ms"):
            raise CaseError("train.resistance.speed_unit", self.speed_unit, "must be 'kmh' or 'ms'")

    def coefficients_si(self, mass_kg: float, g_ms2: float = 9.81) -> tuple[float, float, float]:
        """(A [N], B [N s/m], C [N s^2/m^2]) with v in m/s."""
        scale = 1000.0 if self.unit == "kN" else mass_kg * g_ms2 / 1000.0
        k = KMH_PER_MS if self.speed_unit == "kmh" else 1.0
        return self.a * scale, self.b * scale * k, self.c * scale * k * k

    def force_kn(self, speed_kmh: np.ndarray | float, mass_t: float, g_ms2: float = 9.81) -> np.ndarray:
        """W0 in kN at speeds in km/h (plain numpy, for checks and plots)."""
        a, b, c = self.coefficients_si(mass_t * 1000.0, g_ms2)
        v = np.asarray(speed_kmh, dtype=float) / KMH_PER_MS
        return (a + b * v + c * v * v) / 1000.0
