"""Encodings of a driving strategy as a decision vector, one module each, and their registry.

An encoding is an option object, as pymoo's ``sampling=...``:
``SpeedProfileProblem(case, encoding=SpeedCodes(partition="equal", n_sections=12))``. A name
(``encoding="switching_points"``) is resolved here, in :data:`REGISTRY`, which also gives the
command line its choices. The protocol every encoding follows is in
:mod:`pymoo_rail.problems.encodings.base`.

- :class:`SpeedCodes` (``speed_codes``): one target speed (km/h) per section (Liu (2019) 4.3.3);
- :class:`SwitchingPoints` (``switching_points``): the positions (m) where a regime sequence
  switches (Meng et al. (2017), Tang et al. (2020));
- :class:`BrakingOnset` (``braking_onset``): phases, the braking onset (m) and the deceleration
  (m/s^2), so the stop error varies (Meng et al. (2017));
- :class:`PacedCodes` (``paced_speed_codes``): speed-code shapes and the running time (s), each
  shape paced to its time, so every vector is on time.

Adding an encoding is one module here and one line of :data:`REGISTRY`. This module loads an
encoding's module only when it is asked for, so the command line lists the names at once.
"""

from __future__ import annotations

import dataclasses
import importlib
from typing import Any

from pymoo_rail.problems.lazy import lazy_names

REGISTRY: dict[str, tuple[str, str, str]] = {
    "speed_codes": ("speed_codes", "SpeedCodes", "a target speed per section (km/h)"),
    "switching_points": ("switching_points", "SwitchingPoints", "the positions where a regime sequence switches (m)"),
    "braking_onset": ("braking_onset", "BrakingOnset",
                      "phases, the braking onset (m) and the deceleration (m/s^2): a live stop error"),
    "paced_speed_codes": ("paced_codes", "PacedCodes",
                          "speed-code shapes (share of each limit), then the running time (s): on time"),
}
"""Encoding name -> (module of this package, class, one line for help texts)."""

ENCODINGS = tuple(REGISTRY)
"""Encoding names of ``SpeedProfileProblem``."""

# the other public names of the modules, loaded on first use (see ``__getattr__``)
_MODULE_OF = {"overrun_case": "braking_onset", "sparse_code_floor_kmh": "speed_codes", "PARTITIONS": "speed_codes",
              "EncodingSetup": "base", "Encoding": "base", "ProgramEncoding": "base", "Runner": "base",
              "decision_columns": "base", **{cls: module for module, cls, _ in REGISTRY.values()}}

__all__ = ["REGISTRY", "ENCODINGS", "encoding_names", "encodings_help", "encoding_class", "encoding_settings",
           "make_encoding", "resolve_encoding", *_MODULE_OF]


def encoding_names() -> tuple[str, ...]:
    """The encoding names a problem (and the command line) accepts."""
    return ENCODINGS


def encoding_class(name: str) -> type:
    """The class of an encoding name.

    Raises
    ------
    ValueError
        Naming the encoding and the known names.
    """
    if name not in REGISTRY:
        raise ValueError(f"encoding = {name!r} is unknown (known: {', '.join(ENCODINGS)})")
    module, cls, _ = REGISTRY[name]
    return getattr(importlib.import_module(f"{__name__}.{module}"), cls)


def encodings_help() -> str:
    """One line per encoding, ``name: meaning``, for help texts."""
    return "\n".join(f"{name}: {meaning}" for name, (_, _, meaning) in REGISTRY.items())


def encoding_settings(name: str) -> tuple[str, ...]:
    """The settings an encoding takes (its fields you may give, e.g. ``partition`` for speed codes)."""
    from pymoo_rail.problems.encodings.base import is_setting  # base loads the simulator: only when needed

    return tuple(f.name for f in dataclasses.fields(encoding_class(name)) if is_setting(f))


def make_encoding(name: str, defaults: dict[str, Any] | None = None, **settings) -> Any:
    """The encoding object of a name, with the ``settings`` it takes (its dataclass fields).

    Parameters
    ----------
    name : str
        A name of :data:`REGISTRY`.
    defaults : dict, optional
        The value of each setting that means "not given": a setting the encoding does not take
        is ignored at that value and an error otherwise (``partition="equal"`` means nothing to
        switching points).
    **settings
        Encoding settings by field name (``partition``, ``n_sections``, ``regimes``, ...).

    Raises
    ------
    ValueError
        Naming an unknown encoding, or a setting that does not apply to it.
    """
    cls = encoding_class(name)
    fields = encoding_settings(name)
    defaults = defaults or {}
    foreign = [key for key, value in settings.items()
               if key not in fields and not (key in defaults and _same(value, defaults[key]))]
    if foreign:
        key = foreign[0]
        takers = [n for n in ENCODINGS if key in encoding_settings(n)]
        raise ValueError(f"{key} = {settings[key]!r} does not apply to encoding = {name!r} "
                         f"(it applies to: {', '.join(takers) or 'none'})")
    return cls(**{key: value for key, value in settings.items() if key in fields and value is not None})


def resolve_encoding(encoding: Any, defaults: dict[str, Any] | None = None, **settings) -> Any:
    """The encoding object of a name (through :func:`make_encoding`) or of an object (itself).

    An object holds its own settings, so a setting beside it that is not at its ``defaults``
    value is an error (``SpeedCodes(...)`` with ``partition="equal"`` given to the problem).

    Raises
    ------
    ValueError
        Naming the encoding or the setting.
    """
    if isinstance(encoding, str):
        return make_encoding(encoding, defaults, **settings)
    if not callable(getattr(encoding, "bind", None)):
        raise ValueError(f"encoding = {encoding!r}: give an encoding name ({', '.join(ENCODINGS)}) "
                         "or an encoding object such as SpeedCodes(...)")
    defaults = defaults or {}
    for key, value in settings.items():
        if not (key in defaults and _same(value, defaults[key])):
            raise ValueError(f"{key} = {value!r} beside encoding = {encoding!r}: set it on the encoding object")
    return encoding


def _same(a: Any, b: Any) -> bool:
    return a is b or (isinstance(a, (str, int, float)) and isinstance(b, (str, int, float)) and a == b)


__getattr__, __dir__ = lazy_names(__name__, _MODULE_OF, __all__)
