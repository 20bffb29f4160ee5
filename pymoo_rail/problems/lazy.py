"""Public names of a package loaded from their modules on first use (PEP 562 module ``__getattr__``)."""

from __future__ import annotations

import importlib
from typing import Callable


def lazy_names(package: str, module_of: dict[str, str], public: list[str] | None = None
               ) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """The ``__getattr__`` and ``__dir__`` of ``package`` whose names live in its modules.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    module_of : dict
        Public name -> module of the package that defines it (``{"SpeedCodes": "speed_codes"}``).
    public : list of str, optional
        What ``dir(package)`` lists (default: the names of ``module_of``), e.g. its ``__all__``.

    Returns
    -------
    (callable, callable)
        ``__getattr__(name)`` imports the module and returns the name (``AttributeError`` for an
        unknown one, so ``from package import submodule`` still finds submodules); ``__dir__()``.
    """

    def __getattr__(name: str):
        if name in module_of:
            return getattr(importlib.import_module(f"{package}.{module_of[name]}"), name)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__() -> list[str]:
        return sorted(module_of if public is None else public)

    return __getattr__, __dir__
