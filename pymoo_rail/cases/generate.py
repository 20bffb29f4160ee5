"""Seeded random lines: plausible cases of every kind of service, for tests and scalable benchmarks.

``generate_case(seed, kind)`` draws a line (length, gradient profile, speed limits, curves,
tunnels, neutral sections) and boundary speeds for one of the built-in or TTOBench trains. The
only source of randomness is ``numpy.random.default_rng(seed)``: the same seed and kind give the
same case on every machine (``tests/cases/test_generate.py`` pins a checksum of the content).

Every line is plausible by construction: gradients within the kind's bounds (at most 35 per mille),
limits at most the train's top speed and 300 km/h, the train shorter than every stretch, neutral
sections only on level or falling track away from the ends, boundary speeds below the first and last
limits with a full kilometre (or the kind's shortest stretch) to brake from them. Features that
make the optimum hard, and that tests and benchmarks need, come with set probabilities: a long
descent under low limits (where holding a speed by regenerative braking is optimal), a long climb
taken at full power, and moving boundary speeds.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.cases.toml_case import read_case
from pymoo_rail.model import Case, CaseError, case_to_dict

_HERE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class LineKind:
    """How one kind of line is drawn (lengths in m, gradients in per mille, speeds in km/h)."""

    train_case: str  # built-in case whose train runs the line
    length_m: tuple[float, float]
    limits_kmh: tuple[float, ...]  # limits of ordinary stretches
    low_limits_kmh: tuple[float, ...]  # limits over a long descent
    limit_changes: tuple[int, int]
    gradient_changes: tuple[int, int]
    max_gradient_permille: float
    descent_permille: tuple[float, float]  # a long descent's gradients (magnitude)
    descent_m: tuple[float, float]  # its length
    climb_permille: tuple[float, float]
    climb_m: tuple[float, float]
    curve_radius_m: tuple[float, float]
    min_stretch_m: float  # shortest stretch between changes
    neutral_sections: int  # most per line (0: a DC line)
    neutral_m: tuple[float, float]
    boundary_speeds_kmh: tuple[float, ...]  # moving boundary speeds to draw from (besides rest)
    p_descent: float = 0.5
    p_climb: float = 0.5
    p_moving_ends: float = 0.4


KINDS: dict[str, LineKind] = {
    "metro": LineKind("yizhuang", (800.0, 3000.0), (60.0, 70.0, 80.0), (45.0, 50.0, 55.0), (1, 3), (3, 10),
                      30.0, (20.0, 30.0), (250.0, 600.0), (15.0, 28.0), (250.0, 600.0), (300.0, 1200.0),
                      150.0, 0, (0.0, 0.0), (3.6, 36.0)),
    "suburban": LineKind("yizhuang-ttobench", (2000.0, 8000.0), (70.0, 80.0), (45.0, 50.0, 60.0), (2, 5), (5, 16),
                         30.0, (15.0, 28.0), (600.0, 1500.0), (12.0, 25.0), (500.0, 1500.0), (400.0, 2000.0),
                         200.0, 0, (0.0, 0.0), (3.6, 36.0)),
    "intercity": LineKind("ttobench-ref", (3600.0, 40000.0), (100.0, 110.0, 120.0, 130.0, 140.0), (60.0, 70.0, 80.0),
                          (2, 8), (5, 40), 25.0, (15.0, 23.0), (2000.0, 6000.0), (10.0, 20.0), (1500.0, 5000.0),
                          (800.0, 4000.0), 300.0, 2, (30.0, 150.0), (3.6, 72.0)),
    "high-speed": LineKind("wuguang-crh3", (15000.0, 50000.0), (200.0, 250.0, 300.0), (160.0, 180.0), (2, 6),
                           (5, 30), 20.0, (12.0, 20.0), (3000.0, 8000.0), (10.0, 20.0), (3000.0, 8000.0),
                           (5000.0, 12000.0), 1000.0, 2, (150.0, 400.0), (3.6, 72.0)),
}


def _round(x: float, step: float = 10.0) -> float:
    return float(round(x / step) * step)


def _cuts(rng: np.random.Generator, start: float, end: float, n: int, min_gap: float) -> list[float]:
    """Up to ``n`` sorted cut points in (start, end), at least ``min_gap`` from each other and the ends."""
    cuts: list[float] = []
    for x in np.sort(rng.uniform(start, end, size=n)):
        x = _round(float(x))
        if x - start >= min_gap and end - x >= min_gap and (not cuts or x - cuts[-1] >= min_gap):
            cuts.append(x)
    return cuts


def _tile(points: list[float], values: list[float]) -> tuple[tuple[float, float, float], ...]:
    """Rows ``(start, end, value)`` from cut points (0 and the length included), merging equal neighbours."""
    rows: list[list[float]] = []
    for a, b, v in zip(points[:-1], points[1:], values):
        if rows and rows[-1][2] == v:
            rows[-1][1] = b
        else:
            rows.append([a, b, v])
    return tuple((float(a), float(b), float(v)) for a, b, v in rows)


def _absorb_short(rows: list, min_m: float) -> list:
    """Rows shorter than ``min_m`` (left by overlaying a feature on a profile) joined to their neighbour."""
    out = [list(r) for r in rows]
    k = 0
    while len(out) > 1 and k < len(out):
        if out[k][1] - out[k][0] < min_m:
            if k > 0:
                out[k - 1][1] = out[k][1]
            else:
                out[1][0] = out[0][0]
            del out[k]
        else:
            k += 1
    return [tuple(r) for r in out]


def _intervals(rng: np.random.Generator, length_m: float, count: int, size_m: tuple[float, float],
               margin_m: float) -> list[tuple[float, float]]:
    """Up to ``count`` disjoint intervals of the given sizes, at least ``margin_m`` from the ends."""
    out: list[tuple[float, float]] = []
    for _ in range(count):
        size = _round(rng.uniform(*size_m))
        lo, hi = margin_m, length_m - margin_m - size
        if hi <= lo:
            continue
        a = _round(rng.uniform(lo, hi))
        if all(a + size + margin_m <= c or d + margin_m <= a for c, d in out):
            out.append((a, a + size))
    return sorted(out)


def _value_at(rows, x: float) -> float:
    for a, b, v in rows:
        if a <= x < b:
            return v
    return rows[-1][2]


def _overlay(rows, a, b, pieces):
    """Replace ``rows`` over [a, b] by ``pieces`` (start, end, value)."""
    out = []
    for r0, r1, v in rows:
        if r1 <= a or r0 >= b:
            out.append((r0, r1, v))
            continue
        if r0 < a:
            out.append((r0, a, v))
        if r1 > b:
            out.append((b, r1, v))
    out.extend(pieces)
    out.sort()
    return out


def _split(rng, a, b, values, gap):
    """``values`` over [a, b], on stretches cut at random (each at least ``gap``, or a share of [a, b])."""
    cuts = [a, *_cuts(rng, a, b, len(values) - 1, min(gap, (b - a) / (2 * len(values)))), b]
    return [(c0, c1, values[k]) for k, (c0, c1) in enumerate(zip(cuts[:-1], cuts[1:]))]


def _add_descent(rng, spec, length, gap, margin, grad_rows, limit_rows, features):
    """A long descent under low limits (regenerative holding): the new gradient and limit rows."""
    size = min(_round(rng.uniform(*spec.descent_m)), 0.5 * length)
    a = _round(rng.uniform(margin, max(margin, length - margin - size)))
    b = min(a + size, length - margin)
    if b - a >= 2 * gap:
        n = int(rng.integers(2, 5))
        steep = [-_round(float(rng.uniform(*spec.descent_permille)), 0.5) for _ in range(n)]
        grad_rows = _overlay(grad_rows, a, b, _split(rng, a, b, steep, gap))
        lows = sorted((float(rng.choice(spec.low_limits_kmh)) for _ in range(2)), reverse=True)
        limit_rows = _overlay(limit_rows, a, b, _split(rng, a, b, lows, gap))
        features.append(f"descent {steep} permille over {a:.0f}-{b:.0f} m under {lows} km/h")
    return grad_rows, limit_rows


def _add_climb(rng, spec, length, gap, margin, mild, grad_rows, features):
    """A long climb taken at full power, not over the descent: the new gradient rows."""
    size = min(_round(rng.uniform(*spec.climb_m)), 0.4 * length)
    a = _round(rng.uniform(margin, max(margin, length - margin - size)))
    b = min(a + size, length - margin)
    clear = all(v > -mild or r1 <= a or r0 >= b for r0, r1, v in grad_rows)  # not over the descent
    if b - a >= 2 * gap and clear:
        n = int(rng.integers(1, 4))
        steep = [_round(float(rng.uniform(*spec.climb_permille)), 0.5) for _ in range(n)]
        grad_rows = _overlay(grad_rows, a, b, _split(rng, a, b, steep, gap))
        features.append(f"climb {steep} permille over {a:.0f}-{b:.0f} m")
    return grad_rows


def _neutral_sections(rng, spec, length, train_length_m, grad_rows):
    """Neutral sections drawn at random, kept on level or falling track over the whole train."""
    neutral = []
    for a, b in _intervals(rng, length, int(rng.integers(0, spec.neutral_sections + 1)), spec.neutral_m,
                           max(2000.0, 0.2 * length)):
        # on level or falling track over the whole train: no stall on a climb without power
        under = [v for r0, r1, v in grad_rows if r1 > a - train_length_m and r0 < b]
        if max(under) <= 0.0:
            neutral.append((a, b))
    return neutral


def _boundary_speeds_kmh(rng, spec, limit_rows, features) -> tuple[float, float]:
    """Initial and final speed: from and to rest, or moving, below the limits there with room to brake."""
    initial_kmh = final_kmh = 0.0
    if rng.random() < spec.p_moving_ends:
        speed = float(rng.choice(spec.boundary_speeds_kmh))
        first_room = limit_rows[0][1] - limit_rows[0][0]
        last_room = limit_rows[-1][1] - limit_rows[-1][0]
        if first_room >= 1000.0 and last_room >= 1000.0:
            initial_kmh = min(speed, limit_rows[0][2])
            final_kmh = min(speed, limit_rows[-1][2])
            features.append(f"moving ends {initial_kmh:g} / {final_kmh:g} km/h")
    return initial_kmh, final_kmh


def generate_case(seed: int, kind: str = "intercity") -> Case:
    """A random but plausible case: a line drawn from ``seed`` for one kind of service.

    Parameters
    ----------
    seed : int
        Seed of ``numpy.random.default_rng``, the only source of randomness: the same seed and kind
        give the same case everywhere.
    kind : {"metro", "suburban", "intercity", "high-speed"}
        The train (the built-in case's: ``yizhuang``, ``yizhuang-ttobench``, ``ttobench-ref`` (the
        391 t VIRM6 intercity with 0.73 efficiency both ways and all braking regenerative),
        ``wuguang-crh3``) and the statistics of the line (:data:`KINDS`).

    Returns
    -------
    Case
        Named ``generated-<kind>-<seed>``, with a planned time about 1.25 x a rough minimum
        (the limits driven at 85 %); the features drawn are listed in ``description``.
    """
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise CaseError("seed", seed, "must be an integer >= 0")
    if kind not in KINDS:
        raise CaseError("kind", kind, f"unknown kind of line (known: {', '.join(KINDS)})")
    spec = KINDS[kind]
    rng = np.random.default_rng(int(seed))
    base = read_case(_HERE / f"{spec.train_case}.toml")
    train = base.train
    length = _round(rng.uniform(*spec.length_m))
    gap = max(spec.min_stretch_m, train.length_m + 10.0)
    top_kmh = min(train.max_speed_kmh, 300.0)
    features = []

    # speed limits: ordinary stretches
    limit_points = [0.0, *_cuts(rng, 0.0, length, int(rng.integers(spec.limit_changes[0], spec.limit_changes[1] + 1)),
                                max(gap, 0.08 * length)), length]
    limits = [min(float(rng.choice(spec.limits_kmh)), top_kmh) for _ in limit_points[:-1]]
    # gradients: a rolling profile
    grad_points = [0.0, *_cuts(rng, 0.0, length,
                               int(rng.integers(spec.gradient_changes[0], spec.gradient_changes[1] + 1)), gap), length]
    mild = min(8.0, spec.max_gradient_permille)
    grads = [_round(float(rng.uniform(-mild, mild)), 0.5) for _ in grad_points[:-1]]
    grad_rows = list(_tile(grad_points, grads))
    limit_rows = list(_tile(limit_points, limits))

    margin = max(gap, 0.1 * length)
    if rng.random() < spec.p_descent:  # a long descent under low limits: regenerative holding
        grad_rows, limit_rows = _add_descent(rng, spec, length, gap, margin, grad_rows, limit_rows, features)
    if rng.random() < spec.p_climb:  # a long climb, taken at full power
        grad_rows = _add_climb(rng, spec, length, gap, margin, mild, grad_rows, features)
    grad_rows, limit_rows = _absorb_short(grad_rows, gap), _absorb_short(limit_rows, gap)
    grad_points = [r[0] for r in grad_rows] + [length]
    grad_rows = list(_tile(grad_points, [r[2] for r in grad_rows]))
    limit_rows = list(_tile([r[0] for r in limit_rows] + [length], [r[2] for r in limit_rows]))

    n_curves = int(rng.integers(0, 1 + max(1, int(length // 2000))))
    curves = tuple((a, b, _round(float(rng.uniform(*spec.curve_radius_m)), 50.0))
                   for a, b in _intervals(rng, length, n_curves, (0.05 * length, 0.15 * length), gap))
    tunnels = tuple(_intervals(rng, length, int(rng.integers(0, 3)), (0.03 * length, 0.12 * length), gap))
    neutral = _neutral_sections(rng, spec, length, train.length_m, grad_rows)

    # boundary speeds: from and to rest, or moving, below the limits there with room to brake
    initial_kmh, final_kmh = _boundary_speeds_kmh(rng, spec, limit_rows, features)

    line = replace(base.line, length_m=length, gradients=tuple(grad_rows), speed_limits=tuple(limit_rows),
                   curves=curves, tunnels=tunnels, neutral_sections=tuple(neutral))
    # a rough minimum running time: every stretch at 85 % of its limit, plus starting and stopping
    rough_s = sum((b - a) / (0.85 * v / KMH_PER_MS) for a, b, v in limit_rows) + 60.0
    planned = _round(1.25 * rough_s, 1.0)
    description = (f"generated {kind} line, seed {seed}: {length / 1000:.2f} km, {len(grad_rows)} gradients, "
                   f"{len(limit_rows)} limits, {len(curves)} curves, {len(tunnels)} tunnels, "
                   f"{len(neutral)} neutral sections" + "".join(f"; {f}" for f in features))
    return Case(name=f"generated-{kind}-{seed}", train=train, line=line, planned_time_s=planned,
                source=f"pymoo_rail.cases.generate_case({seed}, kind={kind!r}); train of the built-in case "
                       f"'{spec.train_case}'", description=description,
                initial_speed_ms=initial_kmh / KMH_PER_MS, final_speed_ms=final_kmh / KMH_PER_MS)


def case_checksum(case: Case) -> str:
    """SHA-256 of a case's content (its dictionary as written to TOML, as sorted JSON): equal cases, equal sums."""
    text = json.dumps(case_to_dict(case), sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()
