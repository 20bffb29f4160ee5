"""Indicators of one front, as stored in each run's record.

Conventions (written down because papers differ):

- ``igd``, ``gd``: pymoo's IGD and GD, i.e. the *mean* Euclidean distance to the nearest point
  (of the front for GD, of the approximation for IGD), in raw objective units.
- ``gd_vv``: Van Veldhuizen's form ``sqrt(sum d_i^2) / n``, the GD of Tang et al. (2020) eq. 13.
- ``hv``: hypervolume of the front normalised by the true front's ideal and nadir points, with
  the reference point 1.1 in every normalised objective (points beyond it add nothing).
- ``spacing``: Schott's spacing (``pymoo_rail.indicators.Spacing``, divides by n - 1, Tang et al. (2020)
  eqs. 11-12), raw objective units; undefined (missing) for fewer than 2 points.
- single objective: ``f_best`` and, where the optimum is known, ``error = f_best - f_opt``.

An indicator that does not apply (no known front, a single point) is left out of the record,
never a number that means nothing; the record says why under ``unavailable``
(:func:`unavailable_indicators`), and the tables show that reason instead of a blank.
"""

from __future__ import annotations

import numpy as np

HV_REFERENCE = 1.1
LOWER_IS_BETTER = {"igd": True, "gd": True, "gd_vv": True, "hv": False, "spacing": True, "f_best": True,
                   "error": True, "energy_gap": True, "energy_gap_max": True, "hv_ratio": False, "energy_gap_pct": True, "n_front": False,
                   "igd_ref": True, "gd_ref": True, "hv_ref": False}


def spacing_indicator():
    """Schott's spacing: ``pymoo_rail.indicators.Spacing``."""
    from pymoo_rail.indicators import Spacing

    return Spacing()


FRONT_INDICATORS = ("igd", "gd", "gd_vv", "hv")


def true_front(problem) -> np.ndarray | None:
    """The problem's known Pareto front (dense where pymoo allows), or None.

    Parameters
    ----------
    problem : pymoo Problem
        Any problem; one without a known front returns ``None`` from pymoo's ``pareto_front`` or
        raises ``NotImplementedError`` (a rail problem without a certified front does).

    Returns
    -------
    numpy.ndarray or None
        The front, shape (n, n_obj), or ``None`` when the problem knows none.
    """
    return true_front_and_reason(problem)[0]


def true_front_and_reason(problem) -> tuple[np.ndarray | None, str]:
    """:func:`true_front` and, when there is none, why (the problem's own words where it gives them)."""
    try:
        try:
            pf = problem.pareto_front(n_pareto_points=1000, use_cache=False)
        except TypeError:  # a front without a size argument
            pf = problem.pareto_front()
    except NotImplementedError as err:  # no known front (pymoo_rail.optimal.reference.NoExactFrontError)
        return None, f"no true front: {err}" if str(err) else "no true front: the problem knows none"
    if pf is None:
        return None, f"no true front: {type(problem).__name__} knows none"
    pf = np.atleast_2d(np.asarray(pf, dtype=float))
    if pf.size == 0 or not np.all(np.isfinite(pf)):
        return None, f"no true front: {type(problem).__name__} gives an empty or non-finite one"
    if pf.shape[1] != problem.n_obj:
        pf = pf.reshape(-1, problem.n_obj)
    return pf, ""


def unavailable_indicators(n_obj: int, n_feasible: int, front_reason: str) -> dict[str, str]:
    """Why each indicator a record leaves out is missing (``front_reason``: from :func:`true_front_and_reason`)."""
    out: dict[str, str] = {}
    if n_feasible == 0:
        names = ("f_best", "error") if n_obj == 1 else (*FRONT_INDICATORS, "spacing")
        return {name: "no feasible solution in the final front" for name in names}
    if front_reason:
        for name in (("error",) if n_obj == 1 else FRONT_INDICATORS):
            out[name] = front_reason
    if n_obj > 1 and n_feasible < 2:
        out["spacing"] = "needs at least 2 feasible points"
    return out


def normalised_hv(F: np.ndarray, ideal: np.ndarray, nadir: np.ndarray) -> float:
    """Hypervolume of ``F`` scaled to [ideal, nadir], reference point 1.1 per objective."""
    from pymoo.indicators.hv import HV

    span = np.where(nadir - ideal > 0, nadir - ideal, 1.0)
    Fn = (F - ideal) / span
    return float(HV(ref_point=np.full(F.shape[1], HV_REFERENCE))(Fn))


def gd_van_veldhuizen(F: np.ndarray, pf: np.ndarray) -> float:
    """Van Veldhuizen's generational distance ``sqrt(sum d_i^2) / n`` of ``F`` to the front ``pf`` (raw units; Tang
    et al. (2020) eq. 13).
    """
    from scipy.spatial.distance import cdist

    d = cdist(F, pf).min(axis=1)
    return float(np.sqrt(np.sum(d * d)) / len(d))


def front_indicators(F: np.ndarray, pf: np.ndarray | None) -> dict[str, float]:
    """Indicators of a feasible front ``F`` (n, m); see the module docstring."""
    out: dict[str, float] = {"n_front": float(len(F))}
    if len(F) == 0:
        return out
    m = F.shape[1]
    if m == 1:
        out["f_best"] = float(F.min())
        if pf is not None:
            out["error"] = float(F.min() - pf.min())
        return out
    if pf is not None:
        from pymoo.indicators.gd import GD
        from pymoo.indicators.igd import IGD

        out["igd"] = float(IGD(pf)(F))
        out["gd"] = float(GD(pf)(F))
        out["gd_vv"] = gd_van_veldhuizen(F, pf)
        out["hv"] = normalised_hv(F, pf.min(axis=0), pf.max(axis=0))
    if len(F) >= 2:
        out["spacing"] = float(spacing_indicator()(F))
    return out


def raw_indicators(F: np.ndarray, pf: np.ndarray, hv_ref_point: np.ndarray) -> dict[str, float]:
    """The indicators papers print for a front ``F`` against a true front ``pf``, all in raw objective units.

    ``sp`` Schott's spacing and ``delta`` Deb's spread (NaN below 2 points), ``gd`` / ``igd`` pymoo's
    mean distances, ``gd_vv`` Van Veldhuizen's form (:func:`gd_van_veldhuizen`) and ``hv`` the
    hypervolume to ``hv_ref_point`` (not normalised, unlike :func:`front_indicators`).
    """
    from pymoo.indicators.gd import GD
    from pymoo.indicators.hv import HV
    from pymoo.indicators.igd import IGD

    from pymoo_rail.indicators import Spread

    F = np.asarray(F, dtype=float)
    spread = len(F) > 1
    return {"sp": float(spacing_indicator()(F)) if spread else float("nan"),
            "delta": float(Spread(pf)(F)) if spread else float("nan"),
            "gd": float(GD(pf)(F)), "gd_vv": gd_van_veldhuizen(F, pf), "igd": float(IGD(pf)(F)),
            "hv": float(HV(ref_point=np.asarray(hv_ref_point, dtype=float))(F))}


def convergence_point(F: np.ndarray, pf: np.ndarray | None) -> dict[str, float]:
    """The cheap per-generation values: best per objective, and IGD / HV where ``pf`` is known."""
    out: dict[str, float] = {}
    if len(F) == 0:
        return out
    for j, value in enumerate(F.min(axis=0)):
        out[f"f{j}_min"] = float(value)
    if pf is not None and F.shape[1] >= 2:
        from pymoo.indicators.igd import IGD

        out["igd"] = float(IGD(pf)(F))
        out["hv"] = normalised_hv(F, pf.min(axis=0), pf.max(axis=0))
    elif pf is not None:
        out["error"] = float(F.min() - pf.min())
    return out


def hv_ratio(F, pf) -> float:
    """Hypervolume of ``F`` over that of the front ``pf`` (both normalised by ``pf``'s ideal and nadir)."""
    F = np.atleast_2d(np.asarray(F, dtype=float))
    pf = np.atleast_2d(np.asarray(pf, dtype=float))
    if F.size == 0:
        return 0.0
    ideal, nadir = pf.min(axis=0), pf.max(axis=0)
    return normalised_hv(F, ideal, nadir) / normalised_hv(pf, ideal, nadir)
