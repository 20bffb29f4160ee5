"""A certified energy / running-time front: its nodes, its certificate between them, its file format.

The front is convex and decreasing in time, so the chord between two nodes lies above it by at most
``h (lambda_left - lambda_right) / 4`` (the tangents at both ends bound it from below):
:meth:`CertifiedFront.energy_at` interpolates and adds that to the nodes' bound. A front is stored
as a commented CSV (:func:`commented_csv_text`, :func:`read_commented_csv`), the one file format of
the shipped and cached fronts, certified and best-known. A front belongs to a case's *content*
(:func:`case_hash`: train, line, planned time; never the name).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from pymoo_rail.model import Case, case_to_dict

class NoExactFrontError(NotImplementedError):
    """The problem has no exact front (e.g. three or more objectives); the message says what exists."""


FRONT_VERSION = "9"
"""Version of the front computation; bump it when the solver (with
:data:`pymoo_rail.optimal.solver.SOLVER_VERSION`) or the node choice changes
(4: every node solved in the sweep and alone, the lower kept, the bound at least their difference;
5: the solver keeps a run with its last switch moved only near the front, its certificate compares
the half grid at the run's price and has a floor of 1e-4 of the energy;
6: nodes also at the ends of the punctuality window, so that the optimum of a single-objective
form is a solved run, not a point on a chord;
7: solver version 3, the certificate's floor on the traction energy;
8: solver version 4, the coast curves and the full-traction start as states;
9: solver version 5, the certificate compares a grid of twice the speed nodes)."""
COLUMNS = ("requested_time_s", "running_time_s", "energy_kwh", "lambda_kwh_per_s", "energy_bound_kwh")


def case_hash(case: Case) -> str:
    """SHA-256 of the case's content (train, line, planned time, dwell, legs): not of its names or prose."""
    data = case_to_dict(case)
    for key in ("name", "source", "description"):
        data.pop(key, None)
    if isinstance(data.get("train"), dict):
        data["train"].pop("name", None)  # the train's name is prose too
    text = json.dumps(data, sort_keys=True, default=repr)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def read_commented_csv(path: str | Path) -> tuple[dict[str, str], pd.DataFrame]:
    """A CSV file whose leading ``# key: value`` lines describe it: (those fields, the table).

    The format of the shipped and cached fronts (certified and best-known).
    """
    meta = {}
    with open(path, encoding="utf-8") as handle:
        for line in handle:
            if not line.startswith("#"):
                break
            key, _, value = line[1:].partition(":")
            meta[key.strip()] = value.strip()
    return meta, pd.read_csv(path, comment="#")


def commented_csv_text(meta: Mapping[str, object], table: pd.DataFrame) -> str:
    """A table as CSV text led by one ``# key: value`` line per field of ``meta`` (read by :func:`read_commented_csv`).

    The format of the shipped and cached fronts (certified and best-known); numbers to 9 significant digits.
    """
    header = "".join(f"# {key}: {value}\n" for key, value in meta.items())
    return header + table.to_csv(index=False, float_format="%.9g")


@dataclass(frozen=True)
class CertifiedFront:
    """The certified energy / running-time front of one case.

    Attributes
    ----------
    table : pandas.DataFrame
        One row per node, sorted by time, with :data:`COLUMNS`.
    case_hash : str
        :func:`case_hash` of the case it belongs to.
    case_name : str
    planned_time_s : float
    dx_m : float
        Simulation step of the solver's grid.
    certificate : str
        ``"solver"`` (the solver's own bound) or ``"two-grid"`` (see the module docstring).
    version : str
        Package and front version that computed it.
    """

    table: pd.DataFrame
    case_hash: str
    case_name: str
    planned_time_s: float
    dx_m: float
    certificate: str
    version: str

    @property
    def time_range_s(self) -> tuple[float, float]:
        """Shortest and longest running time of the front's nodes (s)."""
        t = self.table["running_time_s"].to_numpy()
        return float(t[0]), float(t[-1])

    def clip(self, window_s: tuple[float, float] | None) -> tuple[float, float]:
        """A running-time window cut to the front's range; ends within 0.5 s of the range are moved onto it.

        The nodes are the solver's runs, within 0.05 s of the requested times (never 0.5 s off), so a
        window built by :func:`default_window` may start a few hundredths of a second before the first node.
        """
        lo, hi = self.time_range_s
        if window_s is None:
            return lo, hi
        a, b = (float(v) for v in window_s)
        if a < lo - 0.5 or b > hi + 0.5 or not a < b:
            raise ValueError(f"time window {a:.2f}-{b:.2f} s: the front of '{self.case_name}' covers "
                             f"{lo:.2f}-{hi:.2f} s only")
        return max(a, lo), min(b, hi)

    def energy_at(self, running_time_s) -> tuple[np.ndarray, np.ndarray]:
        """Optimal energy (kWh) and its bound (kWh) at running times inside the front's range.

        Linear interpolation between nodes; the bound adds the chord's largest possible excess
        over the convex front, ``h (lambda_left - lambda_right) / 4``.
        """
        t = np.atleast_1d(np.asarray(running_time_s, dtype=float))
        lo, hi = self.time_range_s
        if np.any(~np.isfinite(t)) or np.any(t < lo - 1e-9) or np.any(t > hi + 1e-9):
            raise ValueError(f"running_time_s = {t.tolist()!r}: the front covers {lo:.2f}-{hi:.2f} s only")
        nodes_t = self.table["running_time_s"].to_numpy()
        nodes_e = self.table["energy_kwh"].to_numpy()
        slope = self.table["lambda_kwh_per_s"].to_numpy()
        bound = self.table["energy_bound_kwh"].to_numpy()
        energy = np.interp(t, nodes_t, nodes_e)
        k = np.clip(np.searchsorted(nodes_t, t, side="right") - 1, 0, len(nodes_t) - 2)
        h = nodes_t[k + 1] - nodes_t[k]
        chord = np.abs(slope[k] - slope[k + 1]) * h / 4.0
        total = np.maximum(bound[k], bound[k + 1]) + chord
        total = np.where(np.isclose(t, nodes_t[k]), bound[k], total)  # a node: its own bound only
        total = np.where(np.isclose(t, nodes_t[k + 1]), bound[k + 1], total)
        return energy, total

    def below_certificate(self, running_time_s, energy_kwh) -> tuple[np.ndarray, np.ndarray]:
        """Which runs lie below the front by more than its certificate, among those it covers.

        Returns ``(inside, below)``: boolean masks over the runs, ``inside`` where the running time
        is in the front's range (and the energy finite), ``below`` where ``E < E*(T) - bound(T)``,
        which a correct certificate never allows.
        """
        t = np.asarray(running_time_s, dtype=float).reshape(-1)
        e = np.asarray(energy_kwh, dtype=float).reshape(-1)
        lo, hi = self.time_range_s
        inside = (t >= lo) & (t <= hi) & np.isfinite(e)
        below = np.zeros_like(inside)
        if inside.any():
            optimum, bound = self.energy_at(t[inside])
            below[inside] = e[inside] < optimum - bound - 1e-9
        return inside, below

    def dense(self, n_points: int = 100, window_s: tuple[float, float] | None = None,
              with_nodes: bool = True) -> pd.DataFrame:
        """The front at ``n_points`` evenly spaced running times in ``window_s``, with each point's bound.

        ``with_nodes`` adds the front's nodes inside the window (its vertices: then there are more than
        ``n_points`` rows); without them there are exactly ``n_points`` (at least 2).
        """
        lo, hi = self.clip(window_s)
        t = np.linspace(lo, hi, max(int(n_points), 2))
        if with_nodes:
            t = np.union1d(t, self.table["running_time_s"].to_numpy())
            t = t[(t >= lo) & (t <= hi)]
        energy, bound = self.energy_at(t)
        return pd.DataFrame({"running_time_s": t, "energy_kwh": energy, "energy_bound_kwh": bound})

    # ------------------------------------------------------------------ file format
    def to_csv_text(self) -> str:
        """The front as a commented CSV (the format of the shipped and cached fronts)."""
        meta = {"case_hash": self.case_hash, "case_name": self.case_name, "planned_time_s": repr(self.planned_time_s),
                "dx_m": repr(self.dx_m), "certificate": self.certificate, "version": self.version,
                "energy_bound_kwh": "bound on |energy_kwh - optimum| at running_time_s (kWh)"}
        return commented_csv_text(meta, self.table.loc[:, list(COLUMNS)])

    @classmethod
    def read_csv(cls, path: str | Path) -> CertifiedFront:
        """Read a front written by :meth:`to_csv_text` (raises ValueError naming the file if malformed)."""
        path = Path(path)
        if not path.read_bytes().endswith(b"\n"):
            raise ValueError(f"{path}: its last line is cut off (an interrupted write)")
        meta, table = read_commented_csv(path)
        missing = [c for c in COLUMNS if c not in table.columns]
        needed = ("case_hash", "case_name", "planned_time_s", "dx_m", "certificate", "version")
        if missing or any(k not in meta for k in needed) or len(table) < 2:
            raise ValueError(f"{path}: not a certified front file (missing columns {missing} or header fields)")
        for column in COLUMNS:
            values = pd.to_numeric(table[column], errors="coerce").to_numpy(dtype=float)
            if not np.isfinite(values).all():
                row = int(np.argmax(~np.isfinite(values)))
                raise ValueError(f"{path}: column '{column}' row {row}: {table[column].iloc[row]!r} is not a number")
        return cls(table, meta["case_hash"], meta["case_name"], float(meta["planned_time_s"]), float(meta["dx_m"]),
                   meta["certificate"], meta["version"])


def constrained_optimum(front: CertifiedFront, tolerance_s: float, n_points: int = 2001,
                        window_s: tuple[float, float] | None = None) -> tuple[float, float, float]:
    """Minimum energy with ``|T - T_plan| <= tolerance_s`` (and T in ``window_s``): (kWh, bound kWh, T s).

    Runs faster than the front's first node (0.5 % above the minimum time) are left out: the
    front falls steeply there, so they cost more than that node.
    """
    lo, hi = front.clip(window_s)
    a = max(front.planned_time_s - tolerance_s, lo)
    b = front.planned_time_s + tolerance_s
    if b > hi + 0.5:
        raise ValueError(f"time_tolerance_s = {tolerance_s}: the window around {front.planned_time_s} s "
                         f"reaches beyond the front's range {lo:.2f}-{hi:.2f} s")
    b = min(b, hi)
    if not a < b:
        raise ValueError(f"time_tolerance_s = {tolerance_s}: the window around {front.planned_time_s} s "
                         f"misses the front's range {lo:.2f}-{hi:.2f} s")
    t = np.union1d(np.linspace(a, b, n_points), front.table["running_time_s"].to_numpy())
    t = t[(t >= a) & (t <= b)]
    energy, bound = front.energy_at(t)
    k = int(np.argmin(energy))
    return float(energy[k]), float(bound[k]), float(t[k])
