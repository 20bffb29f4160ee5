"""Compare tracking controllers: every recommended curve tracked by every controller, train and control period.

The table the papers print (tracking error, comfort, energy, punctuality, stop) from one call::

    table, runs = compare_tracking({"DE": ideal}, {"PID": PID(), "fuzzy PID": FuzzyPID()},
                                   {"nominal": case}, periods_s=(0.2, 1.0))
"""

from __future__ import annotations

from typing import Mapping, Sequence

import pandas as pd

from pymoo_rail.model import Case
from pymoo_rail.control.controllers import Controller
from pymoo_rail.control.tracking import track
from pymoo_rail.sim import Trajectory

TRACKING_METRICS = ("energy_kwh", "running_time_s", "stop_error_m", "jerk_ms2", "max_abs_accel_ms2", "regime_changes",
                    "speed_error_rms_kmh", "speed_error_max_kmh", "control_error_rms_kmh", "control_error_max_kmh")


def tracking_metrics(tracked: Trajectory) -> dict:
    """The :data:`TRACKING_METRICS` of a tracked run (:func:`pymoo_rail.control.track`).

    Energy is net kWh at the wheel; ``jerk_ms2`` the sum of ``|a_i - a_(i-1)|``; speed errors are speed
    minus reference at the same position, over the whole run and over the part the controller drives.
    """
    s = tracked.summary
    return {"energy_kwh": tracked.energy.net_kwh, "running_time_s": tracked.running_time_s,
            "stop_error_m": tracked.stop_error_m, "jerk_ms2": s["jerk_ms2"], "max_abs_accel_ms2": s["max_abs_accel_ms2"],
            "regime_changes": int(s["regime_changes"]), "speed_error_rms_kmh": s["speed_error_rms_kmh"],
            "speed_error_max_kmh": s["speed_error_max_kmh"], "control_error_rms_kmh": s["control_error_rms_kmh"],
            "control_error_max_kmh": s["control_error_max_kmh"]}


def compare_tracking(references: Mapping[str, Trajectory], controllers: Mapping[str, Controller],
                     trains: Mapping[str, Case], periods_s: Sequence[float]) -> tuple[pd.DataFrame, dict]:
    """Track every reference curve with every controller, on every train, at every control period.

    Parameters
    ----------
    references : mapping of str to Trajectory
        The recommended curves by name (ideal runs of the simulator, the exact optimum, ...).
    controllers : mapping of str to Controller
        ``Hysteresis``, ``PID`` or ``FuzzyPID`` by name.
    trains : mapping of str to Case
        The case each curve is tracked on, by name (e.g. the nominal train and a heavier one).
    periods_s : sequence of float
        Control periods (s).

    Returns
    -------
    (pandas.DataFrame, dict)
        One row per tracked run, columns ``curve``, ``train``, ``period_s``, ``controller`` and the
        :data:`TRACKING_METRICS`, in the loop order curve, train, period, controller; and the tracked
        runs by ``(curve, train, period_s, controller)``.
    """
    if not (references and controllers and trains and len(periods_s)):
        raise ValueError("compare_tracking: references, controllers, trains and periods_s must not be empty, got "
                         f"{len(references)}, {len(controllers)}, {len(trains)}, {len(periods_s)}")
    rows, runs = [], {}
    for curve, reference in references.items():
        for train, case in trains.items():
            for period in periods_s:
                for name, controller in controllers.items():
                    tracked = track(case, reference, controller, control_period_s=period)
                    runs[curve, train, period, name] = tracked
                    rows.append({"curve": curve, "train": train, "period_s": period, "controller": name,
                                 **tracking_metrics(tracked)})
    return pd.DataFrame(rows), runs
