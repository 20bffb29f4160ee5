"""Deb's spread (Delta), and its generalisation to more than two objectives."""

from __future__ import annotations

import numpy as np
from pymoo.core.indicator import Indicator
from pymoo.indicators.distance_indicator import derive_ideal_and_nadir_from_pf
from scipy.spatial.distance import cdist, pdist, squareform

from pymoo_rail.indicators._checks import as_front


class Spread(Indicator):
    r"""Deb's spread indicator :math:`\Delta` (Deb et al. 2002, NSGA-II paper, eq. 1).

    For two objectives the points are sorted along the front (by :math:`f_1`, ties by
    :math:`f_2`) and

    .. math::

        \Delta = \frac{d_f + d_l + \sum_{i=1}^{n-1} |d_i - \bar d|}{d_f + d_l + (n - 1)\,\bar d}

    with :math:`d_i` the Euclidean distances between consecutive points, :math:`\bar d`
    their mean, and :math:`d_f`, :math:`d_l` the distances from the extreme points of the
    true front (first and last after the same sort) to the first and last point of the
    set. :math:`\Delta = 0` for a set that is evenly spaced and reaches both extremes.

    For three or more objectives there is no order along the front; the generalised spread
    of Zhou, Jin, Zhang, Sendhoff and Tsang (2006), as in jMetal's ``GeneralizedSpread``, is
    used: :math:`d_i` becomes the distance of point ``i`` to its nearest neighbour in the
    set, the sum runs over all ``n`` points, and the extreme term sums, over objectives
    ``j``, the distance from the true-front point with the largest :math:`f_j` to the
    nearest point of the set.

    Pass a non-dominated set; the indicator measures whatever points it is given.

    Parameters
    ----------
    pf : array_like
        Points of the true (reference) Pareto front, at least two distinct ones.
    zero_to_one : bool
        Normalise ``pf`` and the measured set by ``ideal`` / ``nadir`` first.
    ideal, nadir : array_like, optional
        Normalisation bounds (taken from ``pf`` when not given).

    Examples
    --------
    >>> import numpy as np
    >>> pf = np.column_stack([np.linspace(0, 1, 11), 1 - np.linspace(0, 1, 11)])
    >>> Spread(pf)(np.array([[0.0, 1.0], [0.5, 0.5], [1.0, 0.0]]))
    0.0
    """

    def __init__(self, pf, zero_to_one: bool = False, ideal=None, nadir=None) -> None:
        pf = as_front(pf, name="pf", min_points=2)
        if np.all(pf == pf[0]):
            raise ValueError("pf needs at least two distinct points to define its extremes")
        ideal, nadir = derive_ideal_and_nadir_from_pf(pf, ideal=ideal, nadir=nadir)
        super().__init__(zero_to_one=zero_to_one, ideal=ideal, nadir=nadir)
        self.pf = self.normalization.forward(pf)

        n_obj = pf.shape[1]
        if n_obj == 2:
            order = np.lexsort((self.pf[:, 1], self.pf[:, 0]))
            self.extremes = self.pf[[order[0], order[-1]]]
        else:
            self.extremes = self.pf[np.argmax(self.pf, axis=0)]

    def do(self, F, *args, **kwargs) -> float:
        """Spread of the point set ``F`` (rows are objective vectors).

        Raises
        ------
        ValueError
            If ``F`` has fewer than 2 points, contains NaN / infinite values, or its number
            of objectives differs from the reference front's.
        """
        F = as_front(F, name="F", min_points=2)
        if F.shape[1] != self.pf.shape[1]:
            raise ValueError(
                f"F has {F.shape[1]} objectives but pf has {self.pf.shape[1]}"
            )
        return self._do(self.normalization.forward(F))

    def _do(self, F: np.ndarray, *args, **kwargs) -> float:
        if F.shape[1] == 2:
            F = F[np.lexsort((F[:, 1], F[:, 0]))]
            d = np.linalg.norm(np.diff(F, axis=0), axis=1)
            d_f = float(np.linalg.norm(F[0] - self.extremes[0]))
            d_l = float(np.linalg.norm(F[-1] - self.extremes[1]))
            d_mean = d.mean()
            num = d_f + d_l + np.abs(d - d_mean).sum()
            den = d_f + d_l + len(d) * d_mean
        else:
            D = squareform(pdist(F))
            np.fill_diagonal(D, np.inf)
            d = D.min(axis=1)
            d_ext = cdist(self.extremes, F).min(axis=1).sum()
            d_mean = d.mean()
            num = d_ext + np.abs(d - d_mean).sum()
            den = d_ext + len(d) * d_mean
        # den == 0 needs every point of F on one spot that is also every extreme of pf
        if den == 0.0:
            raise ValueError("Spread is undefined: F and the extremes of pf are one single point")
        return float(num / den)
