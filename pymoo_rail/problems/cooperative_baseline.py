"""The uncoordinated reference: every train exactly energy-optimal alone, on time, nothing shared.

Each train's run is the exact minimum-traction run of its leg at its planned time
(:func:`pymoo_rail.optimal.optimal_profile`, the dynamic-programming reference), solved with the
train's regeneration set to zero: in Chen et al. (2017) regenerated energy only counts when another
train draws it, so a train alone is optimal for traction energy. The solve takes a minute of CPU
per leg on the 1 m grid, so it is an explicit call, made once per case and reused across offsets.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from pymoo_rail.model import Case, CaseError
from pymoo_rail.optimal import optimal_profile
from pymoo_rail.sim import Simulator, Trajectory
from pymoo_rail.sim import cooperation as coop


def without_regeneration(case: Case) -> Case:
    """The same case with the train's regeneration switched off (a train alone gains nothing from it)."""
    return replace(case, train=replace(case.train, regen_efficiency=0.0))


@dataclass(frozen=True, eq=False)
class ExactBaseline:
    """Exact single-train optima of the legs of a case, with nothing shared.

    ``trajectories[k]`` is leg ``k``'s optimal run (simulated without regeneration, so its
    ``energy.net_kwh`` is its traction energy).
    """

    case: Case
    trajectories: tuple[Trajectory, ...]

    @property
    def energies_kwh(self) -> tuple[float, ...]:
        """Traction energy of each train's exact optimum (kWh)."""
        return tuple(t.energy.traction_kwh for t in self.trajectories)

    @property
    def energy_kwh(self) -> float:
        """Sum over the legs (one train per leg)."""
        return float(sum(self.energies_kwh))

    def to_dict(self) -> dict:
        """Plain figures for a record: energies and running times per leg."""
        return {"case": self.case.name, "energies_kwh": list(self.energies_kwh), "energy_kwh": self.energy_kwh,
                "running_times_s": [t.running_time_s for t in self.trajectories]}

    def clocked_pair(self, offset_s: float) -> list:
        """The optimal runs of legs 0 and 1 on the common clock, leg 1's leaving ``offset_s`` later."""
        if len(self.trajectories) != 2:
            raise ValueError(f"a pair needs two legs, the baseline has {len(self.trajectories)}")
        return [coop.clocked_run(Simulator(self.case.leg(k)).model, t, dep, self.case.legs[k].start_m)
                for k, (t, dep) in enumerate(zip(self.trajectories, (0.0, float(offset_s))))]

    def shared_by_chance_kwh(self, offset_s: float, time_step_s: float = 0.1) -> float:
        """What the optimal runs of legs 0 and 1 share anyway when leg 1's leaves ``offset_s`` later."""
        return coop.shared_energy_kwh(self.clocked_pair(offset_s), 1.0, time_step_s)


def exact_baseline(case: Case, **settings) -> ExactBaseline:
    """The exact uncoordinated baseline of every leg of ``case`` (or of the case itself if it has none).

    ``settings`` go to :func:`~pymoo_rail.optimal.optimal_profile` (``dx_m``, ``n_speeds``, ...).
    """
    if not isinstance(case, Case):
        raise TypeError(f"case = {case!r}: must be a pymoo_rail Case")
    legs = [case.leg(k) for k in range(len(case.legs))] if case.legs else [case]
    if not legs:
        raise CaseError("run.legs", (), "no run to solve", case.name)
    trajs = tuple(optimal_profile(without_regeneration(leg), leg.planned_time_s, **settings) for leg in legs)
    for leg, t in zip(legs, trajs):
        if not np.isfinite(t.energy.traction_kwh):
            raise RuntimeError(f"the exact solver returned no finite energy for {leg.name}")
    return ExactBaseline(case=case, trajectories=trajs)
