"""Schott's spacing (SP) with the sample standard deviation (divides by n - 1)."""

from __future__ import annotations

import numpy as np
from pymoo.core.indicator import Indicator
from pymoo.indicators.distance_indicator import derive_ideal_and_nadir_from_pf
from scipy.spatial.distance import pdist, squareform

from pymoo_rail.indicators._checks import as_front


class Spacing(Indicator):
    r"""Schott's spacing indicator (Schott 1995).

    .. math::

        d_i = \min_{j \ne i} \sum_{k=1}^{m} |f_k(i) - f_k(j)|, \qquad
        SP = \sqrt{\frac{1}{n - 1} \sum_{i=1}^{n} (\bar d - d_i)^2}

    ``d_i`` is the city-block (L1) distance from point ``i`` to its nearest neighbour in
    the set. This is Schott's definition and Tang et al. (2020) eqs. 11-12 (whose text calls ``d_i``
    Euclidean, while its formula is L1; the formula is implemented). SP = 0 means all
    nearest-neighbour gaps are equal. Smaller is better.

    Difference from pymoo: ``pymoo.indicators.spacing.SpacingIndicator`` uses the same
    ``d_i`` but divides by ``n`` (population standard deviation), so its value is
    ``sqrt((n - 1) / n)`` times this one.

    Parameters
    ----------
    pf : array_like, optional
        Reference front, used only to derive ``ideal`` and ``nadir`` for normalisation.
    zero_to_one : bool
        Normalise objectives with ``ideal`` and ``nadir`` before measuring.
    ideal, nadir : array_like, optional
        Normalisation bounds (taken from ``pf`` when not given).

    Examples
    --------
    >>> import numpy as np
    >>> Spacing()(np.array([[0.0, 4.0], [1.0, 2.0], [4.0, 0.0]]))  # sqrt(4/3)
    1.1547005383792515
    """

    def __init__(self, pf=None, zero_to_one: bool = False, ideal=None, nadir=None) -> None:
        if pf is not None:
            pf = as_front(pf, name="pf", min_points=1)
        ideal, nadir = derive_ideal_and_nadir_from_pf(pf, ideal=ideal, nadir=nadir)
        super().__init__(zero_to_one=zero_to_one, ideal=ideal, nadir=nadir)

    def do(self, F, *args, **kwargs) -> float:
        """Spacing of the point set ``F`` (rows are objective vectors).

        Raises
        ------
        ValueError
            If ``F`` has fewer than 2 points or contains NaN / infinite values.
        """
        F = as_front(F, name="F", min_points=2)
        return self._do(self.normalization.forward(F))

    def _do(self, F: np.ndarray, *args, **kwargs) -> float:
        D = squareform(pdist(F, metric="cityblock"))
        np.fill_diagonal(D, np.inf)
        d = D.min(axis=1)
        return float(np.sqrt(np.sum((d - d.mean()) ** 2) / (len(d) - 1)))
