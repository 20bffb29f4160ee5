"""Braking onset: the phases of Meng et al. (2017) with the braking onset (m) and deceleration (m/s^2) as decisions.

The train runs traction, cruise and coast, then brakes at the chosen deceleration and stops where
the physics puts it, short of the platform or past it in an overrun zone, so the stop error is a
consequence of the decision (with the other encodings the kernel lands every run exactly on the
platform and the stop error is always 0).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from pymoo_rail.model import Case, Line
from pymoo_rail.problems.encodings.base import EncodingSetup, ProgramEncoding, bound_field
from pymoo_rail.sim import Simulator, Trajectory, braking_programs
from pymoo_rail.sim import kernel as k


def overrun_case(case: Case, overrun_m: float) -> Case:
    """The case with its line continued ``overrun_m`` past the platform (last gradient and limit).

    The simulated track of :class:`BrakingOnset`: a train that brakes too gently stops in it.
    """
    if not (np.isfinite(overrun_m) and overrun_m > 0):
        raise ValueError(f"overrun_m = {overrun_m!r} must be a positive number")
    line = case.line
    end = float(line.length_m) + float(overrun_m)

    def stretch(rows):
        rows = [list(r) for r in rows]
        rows[-1][1] = end
        return tuple(tuple(r) for r in rows)

    longer = Line(length_m=end, gradients=stretch(line.gradients), speed_limits=stretch(line.speed_limits),
                  curves=line.curves, tunnels=line.tunnels, neutral_sections=line.neutral_sections,
                  gradient_model=line.gradient_model)
    return replace(case, line=longer, legs=())


@dataclass(frozen=True, eq=False)
class BrakingOnset(ProgramEncoding):
    """Phases before braking, the braking onset (m) and the braking deceleration (m/s^2).

    Decision vector: ``len(regimes) - 1`` switching positions between the regimes run before
    braking, then the braking onset (all sorted together, so the onset is the largest), then the
    service deceleration. The train is simulated on the line continued ``overrun_m`` past the
    platform (:func:`overrun_case`): from the onset it brakes at that deceleration and stops where
    it stops; the stop error is its distance to the platform, either way. The braking envelope of
    every speed limit still holds over the whole train (a limit ahead brakes the train harder than
    asked); a train that would run beyond the overrun zone is stopped at its end by the envelope
    (stop error ``overrun_m``).

    Parameters
    ----------
    regimes : tuple of str, optional
        The regimes run before braking (default traction, hold, coast).
    decel_range_ms2 : (float, float), optional
        Bounds of the deceleration; default [0.5, d_max] m/s^2 with d_max the train's service
        deceleration cap (``max_decel_ms2``, 1.0 when the case gives none).
    overrun_m : float
        Length of the overrun zone past the platform (default 20 m).

    Attributes
    ----------
    platform_m : float
        Set by :meth:`bind`: where the platform is (the case's line length).
    simulator : Simulator
        Set by :meth:`bind`: the simulator of the line with its overrun zone.
    xl, xu : numpy.ndarray
        Set by :meth:`bind`: positions in [0, platform], the deceleration in ``decel_range_ms2``.
    """

    regimes: tuple[str, ...] | None = None
    decel_range_ms2: tuple[float, float] | None = None
    overrun_m: float = 20.0
    platform_m: float | None = bound_field()
    simulator: Simulator | None = bound_field()
    xl: np.ndarray | None = bound_field()
    xu: np.ndarray | None = bound_field()

    name = "braking_onset"

    @classmethod
    def build(cls, case: Case, regimes: tuple[str, ...] | None = None,
              decel_range_ms2: tuple[float, float] | None = None, overrun_m: float = 20.0,
              dx_m: float | None = None) -> BrakingOnset:
        """``BrakingOnset(...)`` bound to ``case`` on a grid of ``dx_m`` (see :meth:`bind`)."""
        return cls(regimes, decel_range_ms2, overrun_m).bind(EncodingSetup(case, dx_m=dx_m))

    def bind(self, setup: EncodingSetup) -> BrakingOnset:
        """Bounds: positions in [0, platform]; deceleration in ``decel_range_ms2``; the overrun track's simulator."""
        self.refuse_tracking(setup, "the controllers track an ideal curve that ends at the platform; "
                                    "use speed_codes or switching_points")
        case = setup.case
        regimes = ("traction", "hold", "coast") if self.regimes is None else tuple(self.regimes)
        if not regimes:
            raise ValueError("regimes = (): at least one regime must run before braking")
        decel_range_ms2 = self.decel_range_ms2
        if decel_range_ms2 is None:
            d_max = case.train.max_decel_ms2 if case.train.max_decel_ms2 is not None else 1.0
            decel_range_ms2 = (min(0.5, d_max), d_max)
        lo, hi = (float(v) for v in decel_range_ms2)
        if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo <= hi):
            raise ValueError(f"decel_range_ms2 = {decel_range_ms2!r}: need 0 < low <= high")
        platform = float(case.line.length_m)
        simulator = Simulator(overrun_case(case, self.overrun_m), setup.dx_m)
        n_pos = len(regimes)
        xl = np.concatenate([np.zeros(n_pos), [lo]])
        xu = np.concatenate([np.full(n_pos, platform), [hi]])
        return replace(self, regimes=regimes, overrun_m=float(self.overrun_m), platform_m=platform,
                       simulator=simulator, xl=xl, xu=xu)

    @property
    def units(self) -> list[str]:
        """Unit of each decision variable: positions (m), then the deceleration (m/s^2)."""
        return ["m"] * (self.n_var - 1) + ["m/s^2"]

    def programs(self, X: np.ndarray) -> np.ndarray:
        """Simulator programs of ``X`` (switching points and braking onset in m, deceleration last)."""
        self.bound()
        X = np.atleast_2d(np.asarray(X, dtype=float))
        return braking_programs(X[:, :-1], self.regimes, X[:, -1], self.simulator.length_m)

    def summaries(self, X: np.ndarray, runner=None) -> np.ndarray:
        """Summaries on the overrun track, stop error measured from the platform (short or past it).

        ``runner`` is not used: the runs are on this encoding's own, longer track.
        """
        s = self.simulator.run_batch(self.programs(np.ascontiguousarray(X)))
        s[:, k.OUT_STOP_ERROR_M] = np.abs(s[:, k.OUT_STOP_POSITION_M] - self.platform_m)
        return s

    def trajectory(self, x: np.ndarray, runner=None) -> Trajectory:
        """The trajectory of one decision vector on the overrun track, stop error measured from the platform."""
        tr = self.simulator.run(self.programs(np.asarray(x, dtype=float)[None, :])[0])
        stop = tr.summary["stop_position_m"]
        error = abs(stop - self.platform_m)
        return replace(tr, stop_error_m=error, summary={**tr.summary, "stop_error_m": error})
