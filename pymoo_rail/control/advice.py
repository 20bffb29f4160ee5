"""Driver advice: the optimal policy turned into instructions a driver can follow.

A driver cannot follow a force. :func:`advice_from_run` cuts a run into regimes with switch
positions ("power to 80 km/h", "hold 72 km/h from km 0.45", "coast from km 1.20", "brake for the
stop from km 2.10"), merging any regime shorter than ``min_duration_s`` into its neighbour.
:class:`AdvisedDriving` is the closed loop of a driver following advice: the policy re-plans every
``decide_every_s`` seconds (and on announcements), the advice shown changes only when it differs
from what is shown by more than the hysteresis (another regime, or a switch or speed moved by more
than ``switch_band_m`` / ``speed_band_kmh``) and has been shown for ``min_duration_s``, and the
driver acts ``reaction_s`` after each switch point. The advice is exported as a table
(:func:`advice_frame`, CSV or JSON).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.control.closed_loop import DEFAULT_DECIDE_EVERY_S, LoopState, plan_for
from pymoo_rail.control.estimation import ResistanceEstimator
from pymoo_rail.control.policy import ARRIVAL_TOL_S, OptimalPolicy
from pymoo_rail.model.errors import FieldError, check_number
from pymoo_rail.sim import Trajectory
from pymoo_rail.sim import kernel as sk

REACTION_S = 1.5
MIN_ADVICE_S = 10.0
ADVICE_WORDS = ("power", "hold", "coast", "brake")  # by the simulator's regime code


@dataclass(frozen=True)
class Advice:
    """One instruction: ``action`` from ``start_m`` on; ``speed_kmh`` is the speed to reach (power),
    to hold (hold) or the speed at the switch (coast, brake)."""

    start_m: float
    action: str
    speed_kmh: float
    final: bool = False  # the braking onto the platform

    def text(self) -> str:
        """The instruction as a driver reads it."""
        where = f"from km {self.start_m / 1000.0:.2f}"
        if self.action == "power":
            return f"power to {self.speed_kmh:.0f} km/h {where}"
        if self.action == "hold":
            return f"hold {self.speed_kmh:.0f} km/h {where}"
        if self.action == "brake":
            return f"brake for the stop {where}" if self.final else f"brake to {self.speed_kmh:.0f} km/h {where}"
        return f"coast {where}"

    def same_as(self, other: Advice | None, switch_band_m: float, speed_band_kmh: float) -> bool:
        """Whether ``other`` says the same within the hysteresis bands (no change to show).

        Coasting and the final braking have no speed to compare; a switch band of ``inf``
        compares what to do now, wherever it started.
        """
        if other is None or other.action != self.action or other.final != self.final:
            return False
        if abs(other.start_m - self.start_m) > switch_band_m:
            return False
        return self.action == "coast" or self.final or abs(other.speed_kmh - self.speed_kmh) <= speed_band_kmh


def advice_from_run(run: Trajectory, min_duration_s: float = 5.0, speed_band_kmh: float = 3.0) -> tuple[Advice, ...]:
    """The regimes of a run as advice, merging any pull or brake shorter than ``min_duration_s`` into the regime before.

    A pull or hold is "power to" the speed reached when the speed rises by more than
    ``speed_band_kmh`` over it, else "hold" the speed it starts at; the last braking is the stop.
    """
    check_number("min_duration_s", min_duration_s, nonneg=True, error=FieldError)
    x = np.asarray(run.position_m, dtype=float)
    t = np.asarray(run.time_s, dtype=float)
    v_kmh = np.asarray(run.speed_ms, dtype=float) * KMH_PER_MS
    regime = np.asarray(run.regime[:-1], dtype=int)  # per cell
    if regime.size == 0:
        return ()
    starts = np.concatenate([[0], np.flatnonzero(np.diff(regime)) + 1])
    segments = [[int(s), int(e), int(regime[s])] for s, e in zip(starts, np.append(starts[1:], regime.size))]
    merged: list[list[int]] = []
    for seg in segments:
        short = t[seg[1]] - t[seg[0]] < min_duration_s
        final = seg[2] == sk.REGIME_BRAKE and seg[1] == regime.size
        # a short pull or brake is driven as the regime before it; a coast is never turned into a
        # pull (it is where the energy is saved), nor is the stop
        if merged and (seg[2] == merged[-1][2] or (short and seg[2] != sk.REGIME_COAST and not final)):
            merged[-1][1] = seg[1]
        else:
            merged.append(seg)
    # a short first regime takes the next one's place instead
    if len(merged) > 1 and t[merged[0][1]] - t[merged[0][0]] < min_duration_s and merged[0][2] != sk.REGIME_TRACTION:
        merged[1][0] = merged[0][0]
        merged.pop(0)
    out = []
    for k, (s, e, r) in enumerate(merged):
        action = ADVICE_WORDS[r]
        if action == "power" and v_kmh[e] - v_kmh[s] <= speed_band_kmh:
            action = "hold"  # pulling (with short holds merged in) that barely changes the speed
        elif action == "hold" and v_kmh[e] - v_kmh[s] > speed_band_kmh:
            action = "power"  # holding (with short pulls merged in) that gains speed
        if action == "power":
            speed = v_kmh[e]
        elif action == "hold":
            speed = v_kmh[s]  # the speed to keep (a short brake merged in lowers its mean, not its aim)
        elif action == "brake" and k < len(merged) - 1:
            speed = v_kmh[e]
        else:
            speed = v_kmh[s]
        out.append(Advice(float(x[s]), action, float(round(speed)), final=action == "brake" and k == len(merged) - 1))
    return tuple(out)


def advice_program(advice: tuple[Advice, ...], speed_at, reaction_s: float, length_m: float) -> np.ndarray:
    """A driving program (``end_m, mode, target_ms``) of a driver following ``advice`` ``reaction_s`` late.

    ``reaction_s`` may be negative: advice announced earlier than the driver's delay.

    ``speed_at(x)`` gives the speed (m/s) at position ``x`` (the run the advice came from), to turn
    the reaction time into the distance travelled meanwhile. Power and hold are ``toward`` their
    speed (pull, then hold it by partial traction); coast is no force; the final brake is the
    latest braking onto the platform (the braking curve), another brake holds its speed by braking.
    """
    rows = []
    for k, a in enumerate(advice):
        if k + 1 < len(advice):
            nxt = advice[k + 1].start_m
            end = min(max(nxt + float(speed_at(nxt)) * reaction_s, a.start_m), length_m)
        else:
            end = length_m
        if a.action in ("power", "hold"):
            rows.append((end, sk.MODE_TOWARD, a.speed_kmh / KMH_PER_MS))
        elif a.action == "brake" and not a.final:
            rows.append((end, sk.MODE_HOLD_BRAKE, 0.0))
        else:  # coast; the final braking is the braking envelope's
            rows.append((end, sk.MODE_COAST, 0.0))
    program = np.array(rows, dtype=float)
    program[-1, 0] = max(program[-1, 0], length_m)
    return program


def advice_frame(advice) -> pd.DataFrame:
    """Advice as a table, for CSV or JSON: ``Advice`` items, or ``(time_s, position_m, Advice)`` items
    (:meth:`AdvisedDriving.seen`: ``shown_s`` and ``shown_m`` say when and where it was shown)."""
    rows = []
    for item in advice:
        shown_s, shown_m, a = item if isinstance(item, tuple) else (math.nan, math.nan, item)
        rows.append({"shown_s": shown_s, "shown_m": shown_m, "start_m": a.start_m, "action": a.action,
                     "speed_kmh": a.speed_kmh, "text": a.text()})
    return pd.DataFrame(rows, columns=["shown_s", "shown_m", "start_m", "action", "speed_kmh", "text"])


@dataclass
class AdvisedDriving:
    """A driver following the policy's advice in the closed loop (a controller giving a program).

    Parameters
    ----------
    policy : OptimalPolicy
    decide_every_s : float
        Re-planning period (s); announcements re-plan at once.
    reaction_s : float
        The driver acts this long after each switch point of the advice shown.
    min_duration_s : float
        Each advice shown stays at least this long unless the train reaches its end, and regimes
        shorter than this are merged away.
    lead_s : float
        The display announces each switch this long before the policy's switch point (a driver
        whose delay it knows then acts on the point); 0: at the point.
    switch_band_m, speed_band_kmh : float
        Hysteresis: a re-plan whose advice differs by less than this is not shown (the switch
        band only where advice is listed, :meth:`shown`).
    estimator : ResistanceEstimator or None
        The running resistance the planner uses, estimated from the run so far (None: the case's).

    Attributes
    ----------
    boards : list of (time_s, position_m, tuple of Advice)
        The advice on the driver's display from each decision on (:meth:`seen` lists what the
        driver saw change along a run, :meth:`changes` counts it).
    """

    policy: OptimalPolicy
    decide_every_s: float = DEFAULT_DECIDE_EVERY_S
    reaction_s: float = REACTION_S
    min_duration_s: float = MIN_ADVICE_S
    lead_s: float = 0.0
    switch_band_m: float = 50.0
    speed_band_kmh: float = 3.0
    name: str = "advice"
    tracker: None = None
    estimator: ResistanceEstimator | None = field(default_factory=ResistanceEstimator)
    boards: list = field(default_factory=list)
    _first_seen: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        check_number("reaction_s", self.reaction_s, nonneg=True, error=FieldError)
        check_number("min_duration_s", self.min_duration_s, nonneg=True, error=FieldError)
        check_number("lead_s", self.lead_s, nonneg=True, error=FieldError)
        check_number("switch_band_m", self.switch_band_m, nonneg=True, error=FieldError)
        check_number("speed_band_kmh", self.speed_band_kmh, nonneg=True, error=FieldError)

    def program(self, state: LoopState) -> np.ndarray:
        """Re-plan, update the advice shown (with hysteresis), and drive it with the reaction delay."""
        rest = plan_for(self.policy, state, self.estimator)
        fresh = advice_from_run(rest, self.min_duration_s, self.speed_band_kmh)
        shown = self.boards[-1][2] if self.boards else ()
        before = current_advice(shown, state.position_m)
        new_now = current_advice(fresh, state.position_m)
        since = self._first_seen.get(id(before), state.elapsed_s)
        held = state.elapsed_s - since < self.min_duration_s
        if not shown or state.event == "announcement" or (
                not held and not new_now.same_as(before, math.inf, self.speed_band_kmh)):
            board = fresh
        else:  # keep what is shown; take the re-plan's later advice only where it really differs
            board = self._keep_current(shown, fresh, state.position_m)
        self.boards.append((state.elapsed_s, state.position_m, board))
        now = current_advice(board, state.position_m)
        self._first_seen.setdefault(id(now), state.elapsed_s)
        x_run, v_run = rest.position_m, rest.speed_ms

        def speed_at(x):
            return np.interp(x, x_run, v_run)

        resistance = self.estimator.factor if self.estimator is not None else None
        board = fit_arrival(board, state, self.policy, self.speed_band_kmh, resistance, self.reaction_s - self.lead_s,
                            speed_at)
        self.boards[-1] = (state.elapsed_s, state.position_m, board)
        now = current_advice(board, state.position_m)
        steps = [Advice(state.position_m, now.action, now.speed_kmh, now.final)]
        if before is not None and not now.same_as(before, math.inf, self.speed_band_kmh):
            # the driver reacts to the new advice late: the old one goes on meanwhile
            steps = [Advice(state.position_m, before.action, before.speed_kmh, before.final),
                     Advice(state.position_m + 1e-6, now.action, now.speed_kmh, now.final)]
        steps += [a for a in board if a.start_m > state.position_m]
        return advice_program(tuple(steps), speed_at, self.reaction_s - self.lead_s, float(x_run[-1]))

    @staticmethod
    def _keep_current(shown: tuple, fresh: tuple, position_m: float) -> tuple:
        # the instruction in force stays; the switches ahead follow the re-plan (a moved switch
        # is no change the driver acts on before reaching it)
        return (current_advice(shown, position_m),) + tuple(a for a in fresh if a.start_m > position_m)

    def seen(self, run: Trajectory) -> list[tuple[float, float, Advice]]:
        """What the driver saw along ``run`` (the closed-loop run driven): (time, position, advice) at each change."""
        if not self.boards:
            return []
        times = np.array([b[0] for b in self.boards])
        out: list[tuple[float, float, Advice]] = []
        for x, t in zip(run.position_m, run.time_s):
            board = self.boards[max(int(np.searchsorted(times, t, side="right")) - 1, 0)][2]
            now = current_advice(board, float(x))
            if not out or not now.same_as(out[-1][2], math.inf, self.speed_band_kmh):
                out.append((float(t), float(x), now))
        return out

    def changes(self, run: Trajectory) -> int:
        """How often the advice the driver saw changed along ``run``."""
        return max(len(self.seen(run)) - 1, 0)


def fit_arrival(board: tuple, state: LoopState, policy: OptimalPolicy, speed_band_kmh: float = 3.0,
                resistance_factor: float | None = None, reaction_s: float = 0.0, speed_at=None) -> tuple:
    """Move the switch into the last coast of ``board`` so that following it arrives at the planned time.

    Merging short regimes away (the short pulls a late train's re-plan asks for) changes the
    arrival; the switch from the last "power" or "hold" into coasting is moved to make up for it
    (by bisection on its position, simulated on the planner's model). A board that only coasts
    from here gets a "hold" of the speed now in front, ended where the time is met.
    ``resistance_factor``: the planner's running resistance (:meth:`OptimalPolicy.replan`);
    ``reaction_s`` and ``speed_at``: the driver's delay and the planned speed by position
    (:func:`advice_program`), so that the switch is fitted for the driver who follows it late.
    """
    speed_at = (lambda x: 0.0) if speed_at is None else speed_at
    if state.elapsed_s >= policy.planned_time_s:
        return board
    model = policy.model_ahead(state.position_m, state.speed_ms, state.restriction, state.mass_t,
                               state.adhesion_factor, resistance_factor)
    length = float(model.position_m[-1])
    remaining = policy.planned_time_s - state.elapsed_s
    now = current_advice(board, state.position_m)
    items = [Advice(state.position_m, now.action, now.speed_kmh, now.final)] + [
        a for a in board if a.start_m > state.position_m]
    coasts = [k for k in range(1, len(items)) if items[k].action == "coast" and items[k - 1].action in ("power", "hold")]
    as_shown = advice_program(tuple(items), speed_at, reaction_s, length)
    out = sk.simulate_batch_serial(model, as_shown[None])[0]
    if out[sk.OUT_REACHED] > 0 and abs(out[sk.OUT_RUNNING_TIME_S] - remaining) <= ARRIVAL_TOL_S:
        return board  # on time as it is: no change to show
    if coasts:
        k = coasts[-1]
    elif items[0].action == "coast":
        items.insert(0, Advice(state.position_m, "hold", float(round(state.speed_ms * KMH_PER_MS)), False))
        k = 1
    else:
        return board
    lo = items[k - 1].start_m + 1e-3
    hi = items[k + 1].start_m - 1e-3 if k + 1 < len(items) else length

    def arrival(switch_m: float) -> float:
        trial = tuple(items[:k]) + (Advice(switch_m, "coast", items[k].speed_kmh),) + tuple(items[k + 1:])
        program = advice_program(trial, speed_at, reaction_s, length)
        out = sk.simulate_batch_serial(model, program[None])[0]
        return out[sk.OUT_RUNNING_TIME_S] if out[sk.OUT_REACHED] > 0 else math.inf

    if not arrival(lo) >= remaining >= arrival(hi):
        return board  # this switch cannot meet the time: the advice stays
    for _ in range(30):  # to a metre or so on a 50 km line
        mid = 0.5 * (lo + hi)
        if arrival(mid) > remaining:
            lo = mid
        else:
            hi = mid
        if hi - lo < 0.5:
            break
    items[k] = Advice(float(round(hi, 1)), "coast", items[k].speed_kmh)
    if items[0].start_m == state.position_m and (now is None or items[0].action != now.action):
        return tuple(items)  # the new hold in front is advice of its own
    return (now,) + tuple(items[1:])


def current_advice(board: tuple, position_m: float) -> Advice | None:
    """The advice of ``board`` in force at ``position_m`` (the last one starting at or before it)."""
    now = [a for a in board if a.start_m <= position_m + 1e-9]
    return now[-1] if now else (board[0] if board else None)
