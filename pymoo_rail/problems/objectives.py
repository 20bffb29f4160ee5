"""The objectives of the speed-profile problems, as one table of records.

Each :class:`Objective` says where its value comes from (a named column of the kernel's run
summary, ``pymoo_rail.sim.OUT_NAMES``), its unit and axis label, the column a table of runs stores
it under, the default scale of the weighted-sum form and whether it measures the running time.
The problems (:func:`pymoo_rail.problems.objective_values`), the plots and the command line read
this table; adding an objective is one record here plus its accumulation in the kernel.

This module imports nothing heavy (no Numba, no pymoo), so the command line lists the objectives
at once.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable, Sequence

SCALE_BASES = ("flat_out", "planned_time", "fixed")


@dataclass(frozen=True)
class Objective:
    """One objective of :class:`~pymoo_rail.problems.SpeedProfileProblem`.

    Attributes
    ----------
    name : str
        The name a user asks for (``objectives=("energy", ...)``).
    unit : str
        Unit of its values (``"kWh"``, ``"s"``, ``"m/s^2"``).
    label : str
        Axis label with the unit.
    column : str
        Column of a table of runs that holds it, unit in the name (``"energy_kwh"``).
    kernel_column : str
        The run-summary column it is read from (an entry of ``pymoo_rail.sim.OUT_NAMES``).
    meaning : str
        One line for help texts.
    aliases : tuple of str
        Other names of the same objective (``"jerk"`` for ``"accel_variation"``).
    off_plan : bool
        The value is ``|kernel value - planned time|`` (the time error), not the kernel value.
    measures_time : bool
        It measures the running time (absolute or off the plan): a single objective without one
        needs a running-time constraint.
    scale_basis : {"flat_out", "planned_time", "fixed"}
        Default scale of the weighted sum: ``scale_factor`` times the flat-out run's value, the
        planned time, or 1.
    scale_factor : float
        See ``scale_basis``.
    """

    name: str
    unit: str
    label: str
    column: str
    kernel_column: str
    meaning: str
    aliases: tuple[str, ...] = ()
    off_plan: bool = False
    measures_time: bool = False
    scale_basis: str = "flat_out"
    scale_factor: float = 1.0

    def __post_init__(self):
        if self.scale_basis not in SCALE_BASES:
            raise ValueError(f"Objective {self.name!r}: scale_basis = {self.scale_basis!r} "
                             f"(known: {', '.join(SCALE_BASES)})")

    def default_scale(self, flat_out_value: float, planned_time_s: float) -> float:
        """Scale of the weighted-sum form, from the flat-out run's value of this objective and the plan."""
        if self.scale_basis == "flat_out":
            return max(self.scale_factor * flat_out_value, 1e-9)  # never 0: it divides
        if self.scale_basis == "planned_time":
            return self.scale_factor * planned_time_s
        return self.scale_factor


# "jerk" is the name Meng et al. (2017) give their comfort figure, sum |a_i - a_(i-1)| (m/s^2): a total
# variation of acceleration, not a rate of change (m/s^3). "accel_variation" says what it is; "jerk"
# stays as an alias of the same objective.
OBJECTIVE_TABLE: tuple[Objective, ...] = (
    Objective("energy", "kWh", "energy (kWh)", "energy_kwh", "net_kwh",
              "net kWh: traction / eta + auxiliary - regenerated (Liu (2019) eq. 4-15)"),
    Objective("running_time", "s", "running time (s)", "running_time_s", "running_time_s",
              "running time (s)", measures_time=True, scale_basis="planned_time"),
    Objective("time_error", "s", "time error |T - T_plan| (s)", "time_error_s", "running_time_s",
              "|T - T_plan| (s, Liu (2019) eq. 4-21)", off_plan=True, measures_time=True,
              scale_basis="planned_time", scale_factor=0.05),  # Meng et al.'s (2017) punctuality tolerance
    Objective("accel_variation", "m/s^2", "total variation of acceleration (m/s²)", "accel_variation_ms2",
              "jerk_ms2", "comfort: sum of |a_i - a_(i-1)| (m/s^2, Meng et al. (2017) eq. 5)",
              aliases=("jerk",)),
    Objective("stop_error", "m", "stop error (m)", "stop_error_m", "stop_error_m",
              "|x_stop - L| (m, Meng et al. (2017) eq. 6)", scale_basis="fixed", scale_factor=0.25),
    Objective("peak_power", "kW", "peak traction power (kW)", "peak_power_kw", "peak_traction_kw",
              "peak electrical traction power drawn (kW): the substation's peak load"),
)
"""Every objective, in the order the help texts list them."""

_BY_NAME = {name: obj for obj in OBJECTIVE_TABLE for name in (obj.name, *obj.aliases)}


def objective_names(aliases: bool = True) -> tuple[str, ...]:
    """The names a user may ask for, each objective followed by its aliases (``aliases=False``: without)."""
    return tuple(n for obj in OBJECTIVE_TABLE for n in ((obj.name, *obj.aliases) if aliases else (obj.name,)))


def get_objective(name: str) -> Objective:
    """The record of an objective name or alias.

    Raises
    ------
    ValueError
        Naming the objective and the known names.
    """
    try:
        return _BY_NAME[name]
    except (KeyError, TypeError):
        raise ValueError(f"objective {name!r} is unknown (known: {', '.join(objective_names())})") from None


def canonical_objective(name: str) -> str:
    """The objective a name stands for (``"jerk"`` -> ``"accel_variation"``; unknown names unchanged)."""
    obj = _BY_NAME.get(name)
    return obj.name if obj is not None else name


def check_objectives(objectives: str | Iterable[str], known: Sequence[str] | None = None) -> tuple[str, ...]:
    """Objective names as a tuple, after checking each is known, not repeated (aliases count) and,
    with ``known``, among those canonical names (what a problem can compute).

    Raises
    ------
    ValueError
        Naming the objectives and what is wrong.
    """
    objectives = (objectives,) if isinstance(objectives, str) else tuple(objectives)
    if not objectives:
        raise ValueError("objectives = (): give at least one objective")
    for name in objectives:
        get_objective(name)
        if known is not None and canonical_objective(name) not in known:
            raise ValueError(f"objective {name!r} is unknown here (known: {', '.join(known)}; "
                             "jerk = accel_variation)")
    if len({canonical_objective(name) for name in objectives}) != len(objectives):
        raise ValueError(f"objectives = {objectives!r} repeats an objective (jerk is an alias of accel_variation)")
    return objectives


def objective_labels() -> dict[str, str]:
    """Axis label of every name and alias (an alias label names itself: ``"jerk: total variation ..."``)."""
    labels = {}
    for obj in OBJECTIVE_TABLE:
        labels[obj.name] = obj.label
        labels.update({alias: f"{alias}: {obj.label}" for alias in obj.aliases})
    return labels


def objective_columns() -> dict[str, str]:
    """Column of a table of runs of each objective (``{"energy": "energy_kwh", ...}``)."""
    return {obj.name: obj.column for obj in OBJECTIVE_TABLE}


def time_objectives() -> tuple[str, ...]:
    """Names (and aliases) of the objectives that measure the running time."""
    return tuple(n for obj in OBJECTIVE_TABLE if obj.measures_time for n in (obj.name, *obj.aliases))


def objectives_help() -> str:
    """One line per objective, ``name (alias ...): meaning``, for help texts."""
    lines = []
    for obj in OBJECTIVE_TABLE:
        alias = f" (alias {', '.join(obj.aliases)})" if obj.aliases else ""
        lines.append(f"{obj.name}{alias}: {obj.meaning}")
    return "\n".join(lines)
