"""Certified energy / running-time fronts of a case, from the exact solver, cached on disk.

A rail problem whose objectives are net energy and running time (or time error) has a known
Pareto front: the minimum energy at each running time, which :mod:`pymoo_rail.optimal` computes.
This sub-package is the one home of that reference: it turns the solver's runs into a front with
a certificate (``compute``, node times in ``nodes``), keeps it (``store``; one file format,
``front``), measures optimisers against it or against the optimum solved at their own running
times (``gap``), and caches the solver's runs at chosen times (``exact_points``):

- **Nodes.** The solver is asked for the minimum-energy run at ``n_times`` running times from just
  above the minimum running time to :data:`FRONT_SPAN` x the planned time (and at the planned time
  itself). Each node is a real run of the simulator: ``running_time_s``, ``energy_kwh`` (net) and
  the front's slope ``lambda_kwh_per_s`` there.
- **Certificate.** ``energy_bound_kwh`` bounds ``|energy_kwh - true optimum|`` at the node's
  running time. When the solver reports this bound (column ``energy_bound_kwh`` of
  :func:`~pymoo_rail.optimal.optimal_front`) it is used (``certificate = "solver"``).
  Otherwise it is the two-grid estimate (``certificate = "two-grid"``): the difference between
  the default grid and one with half the speed nodes at the same requested time. Each node is
  solved twice, in a warm-started sweep over the times and alone; the lower run is kept and the
  bound raised to at least their difference. Either is also raised to at least
  :data:`BOUND_FLOOR_REL` of the energy. The coarse grid errs more than the
  default one (``docs/optimal.md``), so the difference over-estimates the default grid's error;
  it is an estimate, not a proof.
- **Between nodes.** The front is convex and decreasing in time, so the chord between two nodes
  lies above it by at most ``h (lambda_left - lambda_right) / 4`` (the tangents at both ends
  bound it from below). :meth:`CertifiedFront.energy_at` interpolates and adds that to the bound.
- **Cache.** Fronts are keyed by the case's *content* (:func:`case_hash`: train, line, planned
  time; never the name), the simulation step and :data:`FRONT_VERSION`. They are looked up in the
  fronts shipped with the package (``pymoo_rail/suite/fronts``), then in the user cache
  directory (``platformdirs.user_cache_dir("pymoo-rail")/fronts``, or ``$PYMOO_RAIL_CACHE_DIR``),
  and computed and written there (atomically) otherwise.
- **Gaps.** :func:`certified_gap` measures an optimiser's members against the front and counts
  those below it by more than the certificate (a defect of the reference). The gap to an optimum
  solved at a member's own running time is :func:`pymoo_rail.optimal.solved_energy_gap`.
"""

from pymoo_rail.optimal.reference.compute import (
    BOUND_FLOOR_REL,
    COARSE_FACTOR,
    PROGRESS_DELAY_S,
    Progress,
    compute_front,
    default_dx_m,
    front_progress_bar,
)
from pymoo_rail.optimal.reference.exact_points import EXACT_POINT_COLUMNS, exact_points, exact_points_key
from pymoo_rail.optimal.reference.front import (
    COLUMNS,
    FRONT_VERSION,
    CertifiedFront,
    NoExactFrontError,
    case_hash,
    commented_csv_text,
    constrained_optimum,
    read_commented_csv,
)
from pymoo_rail.optimal.reference.gap import ReferenceAtTime, certified_gap, gap_columns, solved_energy_gap
from pymoo_rail.optimal.reference.nodes import (
    DEFAULT_N_TIMES,
    FRONT_SPAN,
    LONG_LINE_M,
    LONG_LINE_N_TIMES,
    PUNCTUAL_TOLERANCE_MIN_S,
    PUNCTUAL_TOLERANCE_REL,
    default_window,
    front_times,
    n_times_for,
    punctual_tolerance_s,
)
from pymoo_rail.optimal.reference.store import (
    CACHE_ENV,
    SHIPPED_DIR,
    cache_dir,
    certified_front,
    find_front,
    forget_fronts,
    front_key,
)

__all__ = ["CertifiedFront", "NoExactFrontError", "ReferenceAtTime", "case_hash", "cache_dir", "certified_front", "certified_gap",
           "commented_csv_text", "compute_front", "constrained_optimum", "default_dx_m", "default_window",
           "exact_points", "exact_points_key", "find_front", "forget_fronts", "front_key", "front_progress_bar",
           "front_times", "gap_columns", "n_times_for", "punctual_tolerance_s", "read_commented_csv",
           "solved_energy_gap", "Progress", "BOUND_FLOOR_REL", "CACHE_ENV", "COARSE_FACTOR", "COLUMNS",
           "DEFAULT_N_TIMES", "EXACT_POINT_COLUMNS", "FRONT_SPAN", "FRONT_VERSION", "LONG_LINE_M", "LONG_LINE_N_TIMES",
           "PROGRESS_DELAY_S", "PUNCTUAL_TOLERANCE_MIN_S", "PUNCTUAL_TOLERANCE_REL", "SHIPPED_DIR"]
