"""The ATO speed controllers as frozen dataclasses.

Each controller is plain data that the tracking kernel reads as an integer code and a parameter
array (:meth:`code`, :meth:`params`); the state machines themselves are Numba functions in
:mod:`pymoo_rail.control.kernel`. Errors are in km/h (the unit of Liu's (2019) A and B and of the
fuzzy universes of Meng et al. (2017)), time in s, and the command is a fraction of the largest traction
(positive) or braking (negative) force the train has at its speed, in [-1, 1].
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from pymoo_rail.model.errors import FieldError, check_number

CTRL_HYSTERESIS, CTRL_PID, CTRL_FUZZY_PID = 0, 1, 2
CONTROLLER_NAMES = ("hysteresis", "pid", "fuzzy_pid")

TERMS = ("NB", "NM", "NS", "ZO", "PS", "PM", "PB")
_T = {name: k - 3 for k, name in enumerate(TERMS)}  # NB = -3 ... PB = +3


def _table(rows: tuple[str, ...]) -> np.ndarray:
    return np.array([[_T[w] for w in row.split()] for row in rows], dtype=float)


# The classic adaptive fuzzy PID rule base as the literature prints it (rows: e from NB to PB;
# columns: ec from NB to PB; one table each for dKp, dKi, dKd), e.g. Liu Jinkun, "Advanced PID
# control and MATLAB simulation". Seed 002 gives its rule base only in a figure.
CLASSIC_RULES = np.stack([
    _table((  # delta Kp
        "PB PB PM PM PS ZO ZO",
        "PB PB PM PS PS ZO NS",
        "PM PM PM PS ZO NS NS",
        "PM PM PS ZO NS NM NM",
        "PS PS ZO NS NS NM NM",
        "PS ZO NS NM NM NM NB",
        "ZO ZO NM NM NM NB NB")),
    _table((  # delta Ki
        "NB NB NM NM NS ZO ZO",
        "NB NB NM NS NS ZO ZO",
        "NB NM NS NS ZO PS PS",
        "NM NM NS ZO PS PM PM",
        "NM NS ZO PS PS PM PB",
        "ZO ZO PS PS PM PB PB",
        "ZO ZO PS PM PM PB PB")),
    _table((  # delta Kd
        "PS NS NB NB NB NM PS",
        "PS NS NB NM NM NS ZO",
        "ZO NS NM NM NS NS ZO",
        "ZO NS NS NS NS NS ZO",
        "ZO ZO ZO ZO ZO ZO ZO",
        "PB NS PS PS PS PS PB",
        "PB PM PM PM PS PS PB")),
])


def symmetric_rules(rules: np.ndarray) -> np.ndarray:
    """Keep the half of a rule base with e < 0 (and e = 0, ec <= 0) and mirror it through the origin.

    The printed tables are (nearly) anti-symmetric, dK(-e, -ec) = -dK(e, ec): they schedule the
    gains on the sign of the error, as for a step response from below. A tracking error takes
    both signs, so the default rule base makes the increments depend only on ``|e|`` and on whether
    the error grows or shrinks: rule(e, ec) = rule(-e, -ec).
    """
    out = np.array(rules, dtype=float)
    for i in range(7):
        for j in range(7):
            if i > 3 or (i == 3 and j > 3):
                out[:, i, j] = out[:, 6 - i, 6 - j]
    return out


SYMMETRIC_RULES = symmetric_rules(CLASSIC_RULES)
CLASSIC_RULES.setflags(write=False)
SYMMETRIC_RULES.setflags(write=False)


def _check(name: str, value: object, *, positive: bool = False, upper: float | None = None) -> float:
    """A finite, non-negative (or positive) float, else a FieldError (a ValueError) naming the parameter."""
    return check_number(name, value, positive=positive, nonneg=True, upper=upper, error=FieldError)


@dataclass(frozen=True)
class Hysteresis:
    """Traction-coast tracking of Liu (2019) (section 5.1.3, fig. 5-2).

    With ``e = v_ref - v`` in km/h: coast once the train is within ``a_kmh`` of the reference
    (``e < A``), apply maximum traction once it has fallen more than ``b_kmh`` below it
    (``e > B``), and keep the previous regime in between, so the speed stays between
    ``v_ref - B`` and ``v_ref - A``.

    The seed's middle part knows only traction and coasting. On a descent a coasting train can
    run away above the reference; then (``e < -overspeed_kmh``) the controller brakes with
    ``brake_fraction`` of the maximum braking force until the speed is back at the reference.

    Parameters
    ----------
    a_kmh, b_kmh : float
        The band, ``0 <= A < B`` (Liu (2019) table 5-7 uses A = 2 and B = 3 ... 6 km/h).
    overspeed_kmh : float
        Speed above the reference that starts braking (not in the seed; default 2 km/h).
    brake_fraction : float
        Fraction of the maximum braking force used then, in (0, 1].
    """

    a_kmh: float = 2.0
    b_kmh: float = 3.0
    overspeed_kmh: float = 2.0
    brake_fraction: float = 0.5

    def __post_init__(self) -> None:
        a = _check("a_kmh", self.a_kmh)
        b = _check("b_kmh", self.b_kmh)
        if a >= b:
            raise ValueError(f"a_kmh = {a} >= b_kmh = {b}: the coast threshold A must be below "
                             "the traction threshold B")
        _check("overspeed_kmh", self.overspeed_kmh)
        _check("brake_fraction", self.brake_fraction, positive=True, upper=1.0)

    @property
    def name(self) -> str:
        """A readable name with the band (km/h)."""
        return f"Hysteresis(A={self.a_kmh:g}, B={self.b_kmh:g})"

    def code(self) -> int:
        """The controller's code for the tracking kernel."""
        return CTRL_HYSTERESIS

    def params(self) -> np.ndarray:
        """The parameters as the tracking kernel reads them: A, B, overspeed (km/h), brake fraction."""
        return np.array([self.a_kmh, self.b_kmh, self.overspeed_kmh, self.brake_fraction], dtype=float)


@dataclass(frozen=True)
class PID:
    """PID on the speed error ``e = v_ref - v`` (km/h), giving a force command in [-1, 1].

    ``u = kp e + ki integral(e dt) + kd de/dt``, clipped to [-1, 1]; +1 is the maximum traction
    force at the current speed, -1 the maximum braking force. The integral stops while the
    command is saturated in the direction of the error (anti-wind-up), and starts from the
    command that holds the speed on entering the tracked part (bumpless transfer).

    Parameters
    ----------
    kp : float
        Proportional gain, 1/(km/h).
    ki : float
        Integral gain, 1/(km/h s).
    kd : float
        Derivative gain, s/(km/h).
    """

    kp: float = 0.5
    ki: float = 0.05
    kd: float = 0.0

    def __post_init__(self) -> None:
        _check("kp", self.kp)
        _check("ki", self.ki)
        _check("kd", self.kd)

    @property
    def name(self) -> str:
        """A readable name with the gains."""
        return f"PID(kp={self.kp:g}, ki={self.ki:g}, kd={self.kd:g})"

    def code(self) -> int:
        """The controller's code for the tracking kernel."""
        return CTRL_PID

    def params(self) -> np.ndarray:
        """The parameters as the tracking kernel reads them: kp, ki, kd."""
        return np.array([self.kp, self.ki, self.kd], dtype=float)


@dataclass(frozen=True)
class FuzzyPID:
    """Adaptive fuzzy PID (Meng et al. (2017), section 3.4, fig. 6): a PID whose gains a fuzzy system tunes.

    The inputs ``e = v_ref - v`` (km/h) and ``ec = de/dt`` (km/h/s) are scaled onto the universe
    [-3, 3] (quantisation factors ``3 / e_range_kmh`` and ``3 / ec_range_kmhs``, saturating
    outside) and fuzzified by seven triangular terms NB NM NS ZO PS PM PB centred on -3 ... 3.
    Each rule (e is X and ec is Y) has the product of the two memberships as its strength; the
    rule table gives the output term, and the increment is the strength-weighted mean of the
    output term centres, scaled by ``dkp`` / ``dki`` / ``dkd`` (the scale factors). The PID then
    runs with ``Kp = kp + dKp``, ``Ki = ki + dKi``, ``Kd = kd + dKd`` (each >= 0).

    Parameters
    ----------
    kp, ki, kd : float
        Base gains (units as :class:`PID`).
    e_range_kmh, ec_range_kmhs : float
        Errors mapped onto the outer terms PB / NB.
    dkp, dki, dkd : float
        Largest gain increments (Meng et al. (2017) uses +-0.05 for Kp and +-0.002 for Ki and Kd in its
        own units).
    rules : (3, 7, 7) array, optional
        Output term (-3 = NB ... +3 = PB) for each (e, ec) pair, one table per gain; defaults to
        :data:`SYMMETRIC_RULES` (None), the classic table made symmetric in the sign of the
        error; pass :data:`CLASSIC_RULES` for the table as printed.
    """

    kp: float = 0.5
    ki: float = 0.05
    kd: float = 0.0
    e_range_kmh: float = 2.0
    ec_range_kmhs: float = 1.0
    dkp: float = 0.3
    dki: float = 0.03
    dkd: float = 0.05
    rules: np.ndarray | None = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        for name in ("kp", "ki", "kd", "dkp", "dki", "dkd"):
            _check(name, getattr(self, name))
        _check("e_range_kmh", self.e_range_kmh, positive=True)
        _check("ec_range_kmhs", self.ec_range_kmhs, positive=True)
        rules = self.rule_tables()
        if rules.shape != (3, 7, 7):
            raise ValueError(f"rules has shape {rules.shape}: it must be (3, 7, 7), one 7 x 7 table per gain")
        bad = np.argwhere(~np.isin(rules, np.arange(-3, 4)))
        if bad.size:
            idx = tuple(int(i) for i in bad[0])
            raise ValueError(f"rules{list(idx)} = {rules[idx]}: output terms are integers from -3 (NB) to 3 (PB)")

    def rule_tables(self) -> np.ndarray:
        """The (3, 7, 7) rule tables in use."""
        return SYMMETRIC_RULES if self.rules is None else np.asarray(self.rules, dtype=float)

    @property
    def name(self) -> str:
        """A readable name with the base gains."""
        return f"FuzzyPID(kp={self.kp:g}, ki={self.ki:g}, kd={self.kd:g})"

    def code(self) -> int:
        """The controller's code for the tracking kernel."""
        return CTRL_FUZZY_PID

    def params(self) -> np.ndarray:
        """The parameters as the tracking kernel reads them: base gains, input ranges, gain steps, then the rule
        tables.
        """
        head = [self.kp, self.ki, self.kd, self.e_range_kmh, self.ec_range_kmhs, self.dkp, self.dki, self.dkd]
        return np.concatenate([np.array(head, dtype=float), self.rule_tables().ravel()])


Controller = Hysteresis | PID | FuzzyPID


@dataclass(frozen=True)
class SpeedFilter:
    """The filter between the speed sensor and a tracking controller (:func:`pymoo_rail.control.kernel.filter_speed`).

    At each control instant the filter predicts the speed from its last estimate, then corrects it
    by ``alpha`` times the residual (measured minus predicted). With ``accelerometer`` (the
    default) the prediction adds the speed change the train's accelerometer measured since the
    last instant (taken as exact), so the filter has no lag at all and leaves
    ``sqrt(alpha / (2 - alpha))`` of the sensor's white noise: 0.23 at the default ``alpha = 0.1``;
    an accelerometer bias ``b`` (m/s^2) would offset the estimate by ``b period / alpha`` (0.02 m/s
    for 0.01 m/s^2 at the 0.2 s control period). Without
    it, the filter is an alpha-beta filter (its own acceleration estimate, corrected by ``beta /
    dt`` times the residual), which lags the controller's own actions by about ``period /
    alpha``; ``beta = alpha^2 / (2 - alpha)`` is Benedict and Bordner's (1962) relation.
    ``SpeedFilter(1.0, 0.0, False)`` passes the measurement through.
    """

    alpha: float = 0.1
    beta: float = 0.1 ** 2 / (2.0 - 0.1)
    accelerometer: bool = True

    def __post_init__(self) -> None:
        _check("speed_filter.alpha", self.alpha, positive=True, upper=1.0)
        _check("speed_filter.beta", self.beta, upper=2.0)
        if not isinstance(self.accelerometer, (bool, np.bool_)):
            raise FieldError("speed_filter.accelerometer", self.accelerometer, "must be True or False")

    def params(self) -> np.ndarray:
        """``(alpha, beta, accelerometer)`` as the tracking kernel reads them."""
        return np.array([self.alpha, self.beta, float(self.accelerometer)], dtype=float)


NO_SPEED_FILTER = SpeedFilter(1.0, 0.0, False)


def filter_params(speed_filter: SpeedFilter | None) -> np.ndarray:
    """The kernel's ``(alpha, beta)`` of ``speed_filter`` (None: no filter); FieldError for anything else."""
    if speed_filter is None:
        return NO_SPEED_FILTER.params()
    if not isinstance(speed_filter, SpeedFilter):
        raise FieldError("speed_filter", speed_filter, "must be a SpeedFilter or None")
    return speed_filter.params()


def make_controller(name: str, **params) -> Controller:
    """A controller by its name in ``CONTROLLER_NAMES`` (``"hysteresis"``, ``"pid"``,
    ``"fuzzy_pid"``) and its fields, e.g. ``make_controller("hysteresis", a_kmh=2, b_kmh=3)``.

    How a study file, which holds plain data, names a controller. Raises ValueError naming an
    unknown name or field.
    """
    classes = dict(zip(CONTROLLER_NAMES, (Hysteresis, PID, FuzzyPID)))
    if name not in classes:
        raise ValueError(f"controller = {name!r}: must be one of {', '.join(CONTROLLER_NAMES)}")
    try:
        return classes[name](**params)
    except TypeError as err:  # an unknown field: say which controller was meant
        raise ValueError(f"controller = {name!r}: {err}") from None


def check_controller(controller: object) -> Controller:
    """The controller itself, or ValueError if it is not one of ours."""
    if not isinstance(controller, (Hysteresis, PID, FuzzyPID)):
        raise ValueError(f"controller = {controller!r}: must be a Hysteresis, PID or FuzzyPID")
    return controller
