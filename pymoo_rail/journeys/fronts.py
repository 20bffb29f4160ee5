"""Energy-time fronts of single sections: convexification and a simulator-based estimate.

A front is a :class:`pandas.DataFrame` with columns ``running_time_s`` and ``energy_kwh`` (the
format of :func:`pymoo_rail.optimal.optimal_front`), read as the piecewise-linear function through
its points. The allocation of a journey's running time needs convex fronts; :func:`convex_front`
takes the lower convex hull. That is the right model of the minimal energy ``E*(T)`` of a section:
``E*`` is convex in T, so a chord between two achievable points bounds ``E*`` from above, and the
hull of achievable points is an upper bound of ``E*`` that is exact at its vertices.
"""

from __future__ import annotations

from typing import Callable, Sequence, Union

import numpy as np
import pandas as pd

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model import Case, CaseError
from pymoo_rail.sim import Simulator
from pymoo_rail.sim import kernel as k

FRONT_COLUMNS = ("running_time_s", "energy_kwh")
STRATEGY_VERSION = "1"
"""Version of :func:`strategy_front`'s answers: bump it whenever the front it returns for a case can
change (the strategies searched, the hull, or the simulator that runs them), so cached fronts
(:func:`pymoo_rail.journeys.section_fronts` with ``cache_path``) stop serving the old rows."""
FrontSource = Union[str, Callable[[Case, np.ndarray], pd.DataFrame], Sequence[pd.DataFrame]]


def check_front(front: pd.DataFrame, name: str = "front") -> pd.DataFrame:
    """Validate a front: the two columns, finite values, at least one point; sorted by time."""
    if not isinstance(front, pd.DataFrame):
        raise CaseError(name, type(front).__name__, "must be a pandas DataFrame with columns "
                                                    "running_time_s and energy_kwh")
    for col in FRONT_COLUMNS:
        if col not in front.columns:
            raise CaseError(f"{name}.{col}", list(front.columns), "column is missing")
    if len(front) == 0:
        raise CaseError(name, 0, "has no points")
    values = front[list(FRONT_COLUMNS)].to_numpy(dtype=float)
    bad = np.argwhere(~np.isfinite(values))
    if bad.size:
        row, col = bad[0]
        raise CaseError(f"{name}.{FRONT_COLUMNS[col]}[{row}]", values[row, col], "must be finite")
    if (values[:, 0] <= 0).any():
        row = int(np.argmax(values[:, 0] <= 0))
        raise CaseError(f"{name}.running_time_s[{row}]", values[row, 0], "must be > 0")
    return front.sort_values("running_time_s", kind="stable").reset_index(drop=True)


def convex_front(front: pd.DataFrame, name: str = "front") -> pd.DataFrame:
    """The lower convex hull of a front's points (its vertices, sorted by running time).

    For each running time only the lowest energy counts; the hull spans the front's whole time
    range, so slopes increase from the first vertex (the shortest time) to the last.
    """
    front = check_front(front, name)
    # lowest energy at each distinct time
    front = front.loc[front.groupby("running_time_s", sort=True)["energy_kwh"].idxmin()].reset_index(drop=True)
    t = front["running_time_s"].to_numpy(dtype=float)
    e = front["energy_kwh"].to_numpy(dtype=float)
    hull: list[int] = []
    for i in range(t.shape[0]):  # Andrew's monotone chain, lower part
        while len(hull) >= 2:
            a, b = hull[-2], hull[-1]
            cross = (t[b] - t[a]) * (e[i] - e[a]) - (e[b] - e[a]) * (t[i] - t[a])
            if cross <= 0.0:
                hull.pop()
            else:
                break
        hull.append(i)
    return front.iloc[hull].reset_index(drop=True)


def convex_fronts(fronts: Sequence[pd.DataFrame]) -> list[pd.DataFrame]:
    """:func:`convex_front` of each front (named ``fronts[k]`` in errors), a front given several times
    taken once: a trip of many sections over few distinct lines repeats the same DataFrame."""
    done: dict[int, pd.DataFrame] = {}
    out = []
    for k, front in enumerate(fronts):
        if id(front) not in done:
            done[id(front)] = convex_front(front, f"fronts[{k}]")
        out.append(done[id(front)])
    return out


def front_energy(front: pd.DataFrame, running_time_s: float | np.ndarray) -> np.ndarray:
    """Energy on the piecewise-linear front at given running times (inside its time range)."""
    t = front["running_time_s"].to_numpy(dtype=float)
    e = front["energy_kwh"].to_numpy(dtype=float)
    x = np.asarray(running_time_s, dtype=float)
    tol = 1e-9 * max(1.0, t[-1])
    if np.any(x < t[0] - tol) or np.any(x > t[-1] + tol):
        raise CaseError("running_time_s", x.tolist() if x.ndim else float(x),
                        f"outside the front's range [{t[0]:.3f}, {t[-1]:.3f}] s")
    return np.interp(x, t, e)


def front_slopes(front: pd.DataFrame) -> np.ndarray:
    """Slopes dE/dT (kWh/s) of the front's segments, one fewer than its points."""
    t = front["running_time_s"].to_numpy(dtype=float)
    e = front["energy_kwh"].to_numpy(dtype=float)
    return np.diff(e) / np.diff(t)


def strategy_programs(length_m: float, cruise_ms: np.ndarray, coast_from_m: np.ndarray) -> np.ndarray:
    """Programs "maximum traction to a cruise speed, hold it, coast from a point, brake at the end".

    ``cruise_ms`` and ``coast_from_m`` are paired (N,) arrays; the braking envelope of the simulator
    brakes onto lower limits and the platform at the latest moment.
    """
    n = cruise_ms.shape[0]
    programs = np.zeros((n, 2, 3))
    programs[:, 0, 0] = coast_from_m
    programs[:, 0, 1] = k.MODE_TOWARD
    programs[:, 0, 2] = cruise_ms
    programs[:, 1, 0] = length_m
    programs[:, 1, 1] = k.MODE_COAST
    return programs


def strategy_front(case: Case, *, dx_m: float | None = None, n_speeds: int = 31, n_coast: int = 31,
                   min_speed_fraction: float = 0.3, max_time_factor: float = 1.5,
                   simulator: Simulator | None = None) -> pd.DataFrame:
    """Convex energy-time front of a section from a direct search over driving strategies.

    Runs every pair of cruise speed (``n_speeds`` from ``min_speed_fraction`` of the train's maximum
    speed up to it) and coasting point (``n_coast`` from 2 % of the section to its end, i.e. no
    coasting) of the strategy maximum traction - speed hold - coast - maximum braking, the structure
    of the energy-optimal run on level track; keeps the runs that reach the platform with a running
    time up to ``max_time_factor`` times the minimum; and returns the lower convex hull of their
    (time, net energy) points. The first vertex is the flat-out run (the minimum running time).

    Columns: ``running_time_s``, ``energy_kwh``, ``cruise_kmh``, ``coast_from_m`` (the strategy of
    each vertex). A legitimate upper estimate of the optimal front (see the module docstring).
    """
    if n_speeds < 2 or n_coast < 2:
        raise CaseError("n_speeds|n_coast", (n_speeds, n_coast), "need at least 2 values each")
    if not 0.0 < min_speed_fraction < 1.0:
        raise CaseError("min_speed_fraction", min_speed_fraction, "must lie in (0, 1)")
    if not max_time_factor > 1.0:
        raise CaseError("max_time_factor", max_time_factor, "must be > 1")
    sim = simulator if simulator is not None else Simulator(case, dx_m)
    length = sim.length_m
    vmax = case.train.max_speed_ms
    speeds = np.linspace(min_speed_fraction * vmax, vmax, n_speeds)
    coast = np.linspace(0.02 * length, length, n_coast)
    cruise, coast_from = (a.ravel() for a in np.meshgrid(speeds, coast, indexing="ij"))
    out = sim.run_batch(strategy_programs(length, cruise, coast_from))
    fastest = sim.check_reachable()  # raises naming the cause (neutral section, descent, mass, climb)
    reached = out[:, k.OUT_REACHED] > 0
    times = out[:, k.OUT_RUNNING_TIME_S]
    keep = reached & (times <= max_time_factor * fastest.running_time_s)
    points = pd.DataFrame({
        "running_time_s": np.append(times[keep], fastest.running_time_s),
        "energy_kwh": np.append(out[keep, k.OUT_NET_KWH], fastest.energy.net_kwh),
        "cruise_kmh": np.append(cruise[keep], vmax) * KMH_PER_MS,
        "coast_from_m": np.append(coast_from[keep], length),
    })
    return convex_front(points, f"front of {case.name}")
