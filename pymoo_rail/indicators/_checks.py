"""Input checks shared by the indicators in this package."""

from __future__ import annotations

import numpy as np


def as_front(F, name: str = "F", min_points: int = 2) -> np.ndarray:
    """Return ``F`` as a finite 2-D float array with at least ``min_points`` rows.

    Parameters
    ----------
    F : array_like
        Objective vectors, one per row. A 1-D array is read as a single point.
    name : str
        Name used in error messages.
    min_points : int
        Smallest number of points the caller can work with.

    Raises
    ------
    ValueError
        If ``F`` has the wrong shape, contains NaN or infinite values, or has fewer than
        ``min_points`` points.
    """
    try:
        A = np.asarray(F, dtype=float)
    except (TypeError, ValueError) as err:
        raise ValueError(f"{name} must be a numeric array of objective vectors: {err}") from err
    if A.ndim == 1:
        A = A[None, :]
    if A.ndim != 2 or A.shape[1] < 1:
        raise ValueError(f"{name} must be a 2-D array (n_points, n_obj), got shape {A.shape}")
    if len(A) < min_points:
        raise ValueError(f"{name} needs at least {min_points} points, got {len(A)}")
    bad = ~np.isfinite(A)
    if bad.any():
        row = int(np.argwhere(bad)[0, 0])
        raise ValueError(f"{name} contains NaN or infinite values (first in row {row}: {A[row]})")
    return A
