"""What every encoding of :class:`~pymoo_rail.problems.SpeedProfileProblem` offers, and what it is given.

An encoding is an option object, as pymoo's ``sampling=...``: its settings are fields
(``SpeedCodes(partition="equal", n_sections=12)``), and the problem *binds* it to its case with
:meth:`Encoding.bind`, which returns a copy with the bounds and everything the decoding needs.
A bound encoding turns decision vectors into kernel programs (:meth:`Encoding.programs`) and
knows the unit of each decision variable. Running the programs is the runner's job (the problem's
:class:`~pymoo_rail.sim.Simulator`, or its ATO tracker); an encoding that must run its programs
itself (on a longer track, or paced to a running time) overrides :meth:`ProgramEncoding.summaries`
and :meth:`ProgramEncoding.trajectory`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar, Protocol

import numpy as np

from pymoo_rail.model import Case
from pymoo_rail.sim import Simulator, Trajectory

COLUMN_SUFFIXES = {"km/h": "kmh", "m/s^2": "ms2", "1": "share"}
"""Unit -> suffix of a table column (``x3_kmh``): units with characters a column name avoids."""


def bound_field(default: Any = None) -> Any:
    """A dataclass field that :meth:`Encoding.bind` sets (bounds, sections, a simulator): not a setting."""
    return field(default=default, metadata={"bound": True})


def is_setting(f) -> bool:
    """Whether a dataclass field of an encoding is a setting a user gives (not set by binding)."""
    return f.init and not f.metadata.get("bound", False)


@dataclass(frozen=True)
class EncodingSetup:
    """What a problem gives an encoding to bind it (see :meth:`Encoding.bind`).

    Attributes
    ----------
    case : Case
        The problem's case.
    simulator : Simulator or None
        The problem's simulator (its grid and kernel model); ``None`` outside a problem.
    dx_m : float or None
        The grid step the problem was asked for (``None``: the simulator's default for a case).
    tracking : bool
        The runs are those of an ATO controller tracking the decoded curve.
    time_range_s : (float, float)
        The running times the problem's constraints accept (infinite ends: no constraint).
    """

    case: Case
    simulator: Simulator | None = None
    dx_m: float | None = None
    tracking: bool = False
    time_range_s: tuple[float, float] = (-np.inf, np.inf)


class Runner(Protocol):
    """Runs kernel programs: :class:`~pymoo_rail.sim.Simulator`, or a tracker behind the same two calls."""

    def run_batch(self, programs: np.ndarray) -> np.ndarray:
        """Summaries (N, N_OUT) of programs (N, rows, 3 or 4)."""

    def run(self, program: np.ndarray) -> Trajectory:
        """The trajectory of one program."""


class Encoding(Protocol):
    """The protocol of an encoding (see the module docstring); :class:`ProgramEncoding` implements most of it."""

    name: ClassVar[str]
    constant_objectives: ClassVar[tuple[str, ...]]

    def bind(self, setup: EncodingSetup) -> Encoding:
        """A copy bound to the problem's case: bounds set, ready to decode."""

    @property
    def xl(self) -> np.ndarray:
        """Lower bounds of the decision variables."""

    @property
    def xu(self) -> np.ndarray:
        """Upper bounds of the decision variables."""

    @property
    def vtype(self) -> type:
        """pymoo's variable type (``float``, or ``int`` for whole numbers)."""

    @property
    def units(self) -> list[str]:
        """Unit of each decision variable."""

    def programs(self, X: np.ndarray) -> np.ndarray:
        """Kernel programs (N, rows, 3 or 4) of decision vectors (N, n_var)."""

    def summaries(self, X: np.ndarray, runner: Runner) -> np.ndarray:
        """Kernel summaries (N, N_OUT) of decision vectors (N, n_var)."""

    def trajectory(self, x: np.ndarray, runner: Runner) -> Trajectory:
        """The trajectory of one decision vector."""


class ProgramEncoding:
    """The shared part of the encodings: bounds, a check that the encoding is bound, running through the runner.

    A subclass is a frozen dataclass whose settings are plain fields and whose ``xl``, ``xu`` and
    other fields set by binding are :func:`bound_field` (``None`` until bound); it implements
    ``bind``, ``programs`` and ``units``.
    """

    name: ClassVar[str] = ""
    constant_objectives: ClassVar[tuple[str, ...]] = ()
    vtype: type = float

    def bound(self) -> None:
        """Raise, naming the encoding, when it has not been bound to a case yet."""
        if getattr(self, "xl", None) is None:
            raise ValueError(f"encoding {self.name!r} is not bound to a case: pass it to "
                             f"SpeedProfileProblem(case, encoding=...) or call .bind(EncodingSetup(case, ...))")

    @property
    def n_var(self) -> int:
        """Number of decision variables."""
        self.bound()
        return self.xl.shape[0]

    def fixed(self) -> np.ndarray:
        """Mask of the genes an algorithm must not change (none, unless the encoding says otherwise)."""
        return np.zeros(self.n_var, dtype=bool)

    def summaries(self, X: np.ndarray, runner: Runner) -> np.ndarray:
        """Kernel summaries (N, N_OUT) of decision vectors: their programs run by ``runner``."""
        return runner.run_batch(self.programs(np.ascontiguousarray(X)))

    def trajectory(self, x: np.ndarray, runner: Runner) -> Trajectory:
        """The trajectory of one decision vector, run by ``runner``."""
        return runner.run(self.programs(np.asarray(x, dtype=float)[None, :])[0])

    def refuse_tracking(self, setup: EncodingSetup, why: str) -> None:
        """Raise, naming the encoding and ``why``, when the problem tracks its runs with a controller."""
        if setup.tracking:
            raise ValueError(f"encoding = {self.name!r} with tracking: {why}")


def decision_columns(encoding: Encoding) -> list[str]:
    """Column names of the decision variables in a table, unit in the name: ``x0_kmh``, ``x5_m``."""
    return [f"x{j}_{COLUMN_SUFFIXES.get(unit, unit)}" for j, unit in enumerate(encoding.units)]
