"""Shared labels, colours and file output of the plots."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Sequence

from pymoo_rail.atomic import atomic_path
from pymoo_rail.problems.objectives import objective_labels

# axis labels with units of the rail objectives (the objective table) and of the indicators
OBJECTIVE_LABELS = objective_labels()
INDICATOR_LABELS = {
    "igd": "IGD", "gd": "GD (mean distance)", "gd_vv": "GD (Van Veldhuizen)", "hv": "hypervolume (normalised)",
    "spacing": "spacing (Schott)", "f_best": "best objective value", "error": "error to the optimum",
    "energy_gap": "energy gap to the optimum (kWh)", "igd_ref": "IGD to the study's reference front",
    "gd_ref": "GD to the study's reference front", "hv_ref": "hypervolume (study reference, normalised)",
}
REGIME_NAMES = ("traction", "hold", "coast", "brake")
REGIME_COLORS = ("tab:red", "tab:blue", "tab:green", "tab:orange")
LIMIT_COLOR = "black"
NEUTRAL_COLOR = "gold"


def objective_label(name: str | None, index: int) -> str:
    """Axis label with unit of objective ``name`` (``f1``, ``f2`` ... when unnamed)."""
    if name is None:
        return f"f{index + 1}"
    return OBJECTIVE_LABELS.get(name, name)


def objective_labels(names: Sequence[str] | None, n_obj: int) -> list[str]:
    """Axis labels of ``n_obj`` objectives; ``ValueError`` when ``names`` has another length."""
    if names is not None and len(names) != n_obj:
        raise ValueError(f"objectives = {list(names)!r}: the front has {n_obj} objectives")
    return [objective_label(None if names is None else names[i], i) for i in range(n_obj)]


def indicator_label(name: str) -> str:
    """Axis label of an indicator (its name when unknown)."""
    return INDICATOR_LABELS.get(name, name)


def save_figure(fig, path: str | Path, dpi: int = 150, close: bool = True, palette: bool = True) -> Path:
    """Save a figure (format from the suffix) through a temporary file, so no half-written image is left.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : str or Path
        Where to write it; the suffix gives the format.
    dpi : int
        Resolution of raster formats.
    close : bool
        Close the figure afterwards (frees memory in long loops).
    palette : bool
        Store a PNG with a 256-colour palette: a plot has few colours, and the file is about a
        third of the full-colour one (committed report figures have a size limit:
        ``docs/architecture.md``).

    Returns
    -------
    Path
        ``path``.
    """
    try:
        with atomic_path(path, suffix=Path(path).suffix) as tmp:
            fig.savefig(tmp, dpi=dpi, bbox_inches="tight")
            if palette and Path(path).suffix.lower() == ".png":
                to_palette_png(tmp)
    finally:
        if close and "matplotlib.pyplot" in sys.modules:  # a figure of new_figure is not pyplot's: nothing to close
            sys.modules["matplotlib.pyplot"].close(fig)
    return Path(path)


def to_palette_png(path: str | Path) -> None:
    """Rewrite a PNG in place with a 256-colour palette (no dithering: flat plot colours stay flat).

    Parameters
    ----------
    path : str or Path
        A PNG file.
    """
    from PIL import Image  # matplotlib's own dependency

    with Image.open(path) as image:
        # the fast octree: a tenth of median cut's CPU on a plot, as close to the full-colour image and
        # smaller; PNG's "optimize" pass would save 2-3 % more for as much CPU again
        quantized = image.convert("RGB").quantize(colors=256, method=Image.Quantize.FASTOCTREE,
                                                  dither=Image.Dither.NONE)
    quantized.save(path, format="PNG")


def new_figure(nrows: int = 1, ncols: int = 1, figsize=(7.0, 4.5), **kwargs):
    """A figure with a constrained layout, made without pyplot.

    The figure is not registered with pyplot (no global figure list to leak into, and the first
    plot of a run does not pay pyplot's import and backend set-up, about 0.2 s); it is saved with
    :func:`save_figure` or ``fig.savefig``.
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=False, **kwargs)
    return fig, axes
