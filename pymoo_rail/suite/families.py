"""Seeded, scalable problem families of the suite: instance ``(family, n_var, seed)``, the same everywhere.

A family draws its line with :func:`pymoo_rail.cases.generate_case` (``seed`` and the family's kind
of service), plans it 10 % above this model's minimum running time (:func:`family_case`) and cuts it into equal sections, one speed code each, as many as ``n_var`` asks. The
certified front is the case's (:func:`pymoo_rail.optimal.reference.certified_front`): the least
energy at each running time is a property of the train on the line, whatever the sections, so
every dimension of an instance has the same known front, computed once per line by the exact
solver and cached on disk under the case's content hash.

- ``generated-<kind>-bi``: net energy (kWh) and running time (s) inside the planner's window
  (:func:`pymoo_rail.optimal.reference.default_window`), ``n_var`` speed codes (km/h).
- ``generated-<kind>-single``: net energy under ``|T - T_plan| <= 1 %`` of the planned time (at least
  1 s), paced speed codes: ``n_var - 1`` shapes and the running time (s); its optimum is certified.
- ``generated-<kind>-3obj``: net energy, running time and comfort (``accel_variation``, m/s^2) in
  the planner's window, ``n_var`` speed codes; its front is *bounded*, not certified
  (:mod:`pymoo_rail.suite.comfort`): an outer bound from the certified energy front and a kinematic
  comfort floor, an inner bound of real runs, and the gap between them (:meth:`FamilyProblem.bounded_front`).

Each instance carries :data:`FAMILY_VERSION` and a checksum of its definition
(:func:`definition`): the case's content hash, the encoding and its sections, the bounds, the
objectives and the constraints. Results of instances with different checksums are not comparable.
The front is not part of the definition: the true front is a property of the instance, and the
certified (or bounded) front is the exact solver's approximation of it, versioned on its own
(:attr:`FamilyProblem.front_version`, like COCO's reference values next to its function
definitions), so a better solver leaves every checksum, and every stored run, as it was.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from pymoo_rail.cases import KINDS, generate_case
from pymoo_rail.model import Case
from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.sim import Simulator
from pymoo_rail.optimal.reference import FRONT_VERSION, NoExactFrontError, case_hash, certified_front, default_window
from pymoo_rail.suite import comfort
from pymoo_rail.suite import problems as named
from pymoo_rail.suite.identity import HV_MARGIN, as_text, checksum_of
from pymoo_rail.suite.trips import TripProblem, trip_problem

FAMILY_VERSION = "2"
"""Version of the family definitions; bumped whenever an instance's definition (and so its checksum) changes.

2: the definition no longer holds the front's version (every checksum changed once)."""
N_VAR_RANGE = (2, 1000)
"""Smallest and largest ``n_var`` of a family instance (the checks and the benchmark cover 10-1000)."""
DEFAULT_N_VAR = 30
DEFAULT_SEED = 1
BI_OBJECTIVES = ("energy", "running_time")
FORMS = ("bi", "single", "trip", "3obj")
PLAN_MARGIN = 1.1
PLAN_ROUND_S = 5.0
"""A family's line is planned :data:`PLAN_MARGIN` x its minimum running time, rounded up to this (s)."""
TRIP_KINDS = ("metro", "suburban")
"""Kinds of line of the whole-trip families (many stops: the short lines)."""


@dataclass(frozen=True)
class Family:
    """One family of seeded instances.

    Attributes
    ----------
    name : str
        ``generated-<kind>-<form>``.
    kind : str
        Kind of line (:data:`pymoo_rail.cases.KINDS`): its train and line statistics.
    form : {"bi", "single", "trip", "3obj"}
        Energy and running time in the planner's window, energy at the planned time (1 %), the
        energy of a whole trip of ``n_var`` sections with a fixed total running time
        (:mod:`pymoo_rail.suite.trips`), or energy, running time and comfort in the planner's window
        (:mod:`pymoo_rail.suite.comfort`).
    """

    name: str
    kind: str
    form: str

    @property
    def summary(self) -> str:
        """One line on what the family is."""
        what = {"bi": "net energy and running time in the planner's window, n_var speed codes",
                "single": "net energy at the planned time (1 %), n_var - 1 paced shapes and the running time",
                "trip": "net energy of a trip of n_var sections, their running times summing to the plan",
                "3obj": "net energy, running time and comfort (accel_variation) in the planner's window, n_var speed "
                        "codes; bounded front"}[self.form]
        return f"seeded {self.kind} lines (pymoo_rail.cases.generate_case): {what}"


FAMILIES: tuple[Family, ...] = (*(Family(f"generated-{kind}-{form}", kind, form)
                                     for form in ("bi", "single") for kind in KINDS),
                                  *(Family(f"generated-{kind}-trip", kind, "trip") for kind in TRIP_KINDS),
                                  *(Family(f"generated-{kind}-3obj", kind, "3obj") for kind in KINDS))
# new families go at the end: list_families() keeps the order of the earlier ones


def list_families() -> list[str]:
    """Names of the suite's scalable families (``generated-<kind>-bi``, ``-single``, ``-trip`` and ``-3obj``)."""
    return [f.name for f in FAMILIES]


def family(name: str) -> Family:
    """The family of a name; ``ValueError`` naming it and the known ones otherwise."""
    for entry in FAMILIES:
        if entry.name == name:
            return entry
    raise ValueError(f"family {name!r} is unknown (known: {', '.join(list_families())})")


def instance_name(family_name: str, n_var: int, seed: int) -> str:
    """The name of an instance, e.g. ``generated-metro-bi-n300-s7``."""
    return f"{family_name}-n{n_var}-s{seed}"


def _check_int(field: str, value, lo: int, hi: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < lo or (hi is not None
                                                                                              and value > hi):
        span = f"in [{lo}, {hi}]" if hi is not None else f">= {lo}"
        raise ValueError(f"{field} = {value!r}: must be an integer {span}")
    return int(value)


class FamilyProblem(SpeedProfileProblem):
    """An instance of a family: a :class:`~pymoo_rail.problems.SpeedProfileProblem` with its identity.

    Attributes
    ----------
    family : str
    seed : int
    version : str
        :data:`FAMILY_VERSION`.
    checksum : str
        SHA-256 of :func:`definition` (hex).
    suite_name : str
        :func:`instance_name`.
    """

    family: str
    seed: int
    version: str
    checksum: str
    suite_name: str

    def certified_front(self):
        """The line's certified front (:meth:`SpeedProfileProblem.certified_front`).

        The 3-objective form gets the line's energy / running-time front too: the energy any of its
        runs needs at its running time, whatever its comfort (the outer bound's energy side).

        Raises
        ------
        NoExactFrontError
            Naming the instance, where the exact solver gives up on its line (it raises
            ``RuntimeError``: "refine the grid"); pymoo's display then leaves the IGD column out.
        """
        try:
            if self.objectives == comfort.COMFORT_OBJECTIVES:  # the line's energy / running-time front
                return certified_front(self.case, self.simulator.grid.dx_m)
            return super().certified_front()
        except NoExactFrontError:
            raise
        except RuntimeError as err:
            raise NoExactFrontError(f"{self.suite_name}: the exact solver gave up on this line ({err}); "
                                    "no certified front: take another seed") from err

    def hv_reference_point(self) -> np.ndarray:
        """The fixed hypervolume reference point: the certified front's nadir plus
        :data:`~pymoo_rail.suite.identity.HV_MARGIN` of its range.

        Taken from the case's bi-objective front in the planner's window (energy kWh, running time s),
        restricted to this problem's objectives: the single-objective form's point is the energy of
        the fastest optimal run plus the margin of the front's energy range.
        The 3-objective form's comfort coordinate runs from the comfort floor at the window's slow end to
        the nadir of the inner (best-known) points (:func:`pymoo_rail.suite.comfort.cached_inner_points`):
        comfort has no window, and smooth uniform-code runs need far less than the runs an optimiser finds.
        """
        front = self.certified_front()
        lo, hi = front.clip(self.bi_window_s)
        energy, _ = front.energy_at(np.array([lo, hi]))
        ideal = {"energy": float(energy.min()), "running_time": lo}
        nadir = {"energy": float(energy.max()), "running_time": hi}
        if "accel_variation" in self.objectives:
            ideal["accel_variation"] = float(comfort.comfort_floor_ms2(hi, **comfort.floor_settings(self))[0])
            nadir["accel_variation"] = float(comfort.cached_inner_points(self)[:, 2].max())
        return np.array([nadir[o] + HV_MARGIN * (nadir[o] - ideal[o]) for o in self.objectives])

    @property
    def front_version(self) -> str:
        """The version of the front this instance's runs are scored against (not part of its checksum).

        :data:`~pymoo_rail.optimal.reference.FRONT_VERSION` of the exact solver's certified fronts; the
        3-objective form's bounded front adds :data:`~pymoo_rail.suite.comfort.COMFORT_FRONT_VERSION`
        (``"<certified>+comfort<bounded>"``).
        """
        if self.objectives == comfort.COMFORT_OBJECTIVES:
            return f"{FRONT_VERSION}+comfort{comfort.COMFORT_FRONT_VERSION}"
        return FRONT_VERSION

    def bounded_front(self) -> comfort.BoundedFront:
        """The 3-objective form's front bounded on both sides, and the gap (:mod:`pymoo_rail.suite.comfort`).

        The inner points are computed once per instance (10,000 evaluations) and cached on disk.
        """
        if self.objectives != comfort.COMFORT_OBJECTIVES:
            raise ValueError(f"{self.suite_name}: objectives {self.objectives}: only the -3obj families have a "
                             "bounded front (the others are certified: certified_front())")
        outer = comfort.outer_points(self.certified_front(), self.bi_window_s, comfort.floor_settings(self))
        return comfort.bound_front(outer, comfort.cached_inner_points(self), self.hv_reference_point())

    def _calc_pareto_front(self, *args, **kwargs):
        """pymoo's hook: the certified front, or for the 3-objective form the inner (best-known) points
        of :meth:`bounded_front`; its outer bound and gap are there."""
        if self.objectives == comfort.COMFORT_OBJECTIVES:
            return comfort.cached_inner_points(self)
        return super()._calc_pareto_front(*args, **kwargs)

    @property
    def bi_window_s(self) -> tuple[float, float]:
        """The planner's running-time window of the case (the bi-objective form's constraint)."""
        return default_window(self.min_running_time_s, self.case.planned_time_s)


def family_case(kind: str, seed: int) -> Case:
    """The line of an instance: :func:`~pymoo_rail.cases.generate_case` with a planner's planned time.

    The planned time is :data:`PLAN_MARGIN` x this model's minimum running time, rounded up to
    :data:`PLAN_ROUND_S` (as the suite's TTOBench sections are planned). The generator's own plan
    (1.25 x a rough estimate, about 1.8 x the minimum on metro lines) puts the slow end of the
    planner's window near 2.3 x the minimum, where the exact solver gave up on some lines
    (``generated-metro`` seed 2, "refine the grid").
    """
    case = generate_case(seed, kind)
    t_min_s = Simulator(case).flat_out().running_time_s
    planned_s = PLAN_ROUND_S * math.ceil(PLAN_MARGIN * t_min_s / PLAN_ROUND_S)
    return replace(case, planned_time_s=float(planned_s),
                   description=f"{case.description}; planned {planned_s:g} s: {PLAN_MARGIN} x the minimum running "
                               f"time, rounded up to {PLAN_ROUND_S:g} s")


def _settings(entry: Family, case: Case, n_var: int) -> dict:
    if entry.form in ("bi", "3obj"):
        return dict(objectives=BI_OBJECTIVES if entry.form == "bi" else comfort.COMFORT_OBJECTIVES, time_window_s="default", encoding="speed_codes", partition="equal",
                    n_sections=n_var)
    return dict(objectives=("energy",), time_tolerance_s=named.tolerance_s(case), encoding=named.SINGLE_ENCODING,
                partition="equal", n_sections=n_var - 1)


def definition(problem: SpeedProfileProblem, family_name: str, seed: int) -> dict:
    """The canonical definition of an instance, the content of its checksum (JSON-ready, floats as text).

    Floats are written as :func:`~pymoo_rail.suite.identity.as_text` (12 significant digits), so the
    last bits of a simulated time (the window's ends come from the flat-out run) do not change the
    checksum across machines. The front's version is not in it (:attr:`FamilyProblem.front_version`).
    """
    text = as_text
    window = problem.time_window_s
    return {"family": family_name, "family_version": FAMILY_VERSION, "seed": int(seed), "n_var": int(problem.n_var),
            "case_hash": case_hash(problem.case), "encoding": problem.encoding.name,
            "sections_m": text(problem.encoding.boundaries_m), "xl": text(problem.xl), "xu": text(problem.xu),
            "objectives": list(problem.objectives), "n_ieq_constr": int(problem.n_ieq_constr),
            "time_window_s": None if window is None else text(window),
            "time_tolerance_s": None if problem.time_tolerance_s is None else text(problem.time_tolerance_s),
            "stop_tolerance_m": problem.stop_tolerance_m}


def get_family_problem(name: str, n_var: int = DEFAULT_N_VAR, seed: int = DEFAULT_SEED) -> FamilyProblem | TripProblem:
    """Instance ``(name, n_var, seed)`` of a family, the same on every machine.

    Parameters
    ----------
    name : str
        One of :func:`list_families`.
    n_var : int
        Number of decision variables, in :data:`N_VAR_RANGE`.
    seed : int
        Seed of the line (:func:`pymoo_rail.cases.generate_case`), >= 0.

    Returns
    -------
    FamilyProblem
        ``pareto_front()`` is the certified front (computed by the exact solver on first use and
        cached on disk), ``checksum`` and ``version`` identify the definition.
    """
    entry = family(name)
    n_var = _check_int("n_var", n_var, N_VAR_RANGE[0], N_VAR_RANGE[1])
    seed = _check_int("seed", seed, 0)
    if entry.form == "trip":
        return _identify(trip_problem(entry.kind, n_var, seed), name, n_var, seed,
                         lambda p: p.definition())
    case = family_case(entry.kind, seed)
    problem = FamilyProblem(case, **_settings(entry, case, n_var))
    if problem.n_var != n_var:  # a guard on the encodings: the family promises exactly n_var variables
        raise RuntimeError(f"{name}: built {problem.n_var} variables for n_var = {n_var}")
    return _identify(problem, name, n_var, seed, lambda p: definition(p, name, seed))


def _identify(problem, name: str, n_var: int, seed: int, describe):
    """Set an instance's family, seed, version, checksum (of ``describe(problem)``) and names."""
    problem.family, problem.seed, problem.version = name, seed, FAMILY_VERSION
    problem.checksum = checksum_of({"family": name, "family_version": FAMILY_VERSION, "seed": int(seed),
                                    "n_var": int(n_var), **describe(problem)})
    problem.suite_name = instance_name(name, n_var, seed)
    problem.suite_version = FAMILY_VERSION
    return problem


def get_problem(name: str, n_var: int | None = None, seed: int | None = None, **kwargs):
    """A suite problem by name: a family instance (``n_var``, ``seed``) or a named problem (``**kwargs``).

    Parameters
    ----------
    name : str
        One of :func:`list_families` or of :func:`pymoo_rail.suite.list_problems`.
    n_var, seed : int, optional
        The instance of a family (defaults :data:`DEFAULT_N_VAR` and :data:`DEFAULT_SEED`); a named
        problem has neither.
    **kwargs
        Settings of a named problem (:func:`pymoo_rail.suite.problems.get_problem`); a family instance
        takes none: it is defined by its name, ``n_var`` and ``seed`` alone.
    """
    if isinstance(name, str) and name in list_families():
        if kwargs:
            raise ValueError(f"{name}: a family instance is defined by n_var and seed alone; "
                             f"{', '.join(sorted(kwargs))} = ... would change it")
        return get_family_problem(name, DEFAULT_N_VAR if n_var is None else n_var,
                                  DEFAULT_SEED if seed is None else seed)
    given = [field for field, value in (("n_var", n_var), ("seed", seed)) if value is not None]
    if given:
        raise ValueError(f"{given[0]} = {n_var if given[0] == 'n_var' else seed!r}: problem {name!r} is not a family "
                         f"(families: {', '.join(list_families())})")
    return named.get_problem(name, **kwargs)
