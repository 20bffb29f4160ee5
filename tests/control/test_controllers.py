"""Controller parameters, the fuzzy inference against its rule tables, and bad input."""

import dataclasses
import math

import numpy as np
import pytest

from pymoo_rail.control import CLASSIC_RULES, PID, SYMMETRIC_RULES, FuzzyPID, Hysteresis, Tracker, track
from pymoo_rail.control.kernel import controller_command, fuzzy_increments


@pytest.mark.parametrize("i, j", [(i, j) for i in range(7) for j in range(7)])
def test_fuzzy_increments_at_term_centres_are_the_table(i, j):
    """At the centre of term i for e and term j for ec only one rule fires, fully."""
    c = FuzzyPID(e_range_kmh=3.0, ec_range_kmhs=1.5, dkp=0.3, dki=0.03, dkd=0.06, rules=CLASSIC_RULES)
    e, ec = (i - 3) * 3.0 / 3.0, (j - 3) * 1.5 / 3.0
    d = fuzzy_increments(c.params(), e, ec)
    assert d == pytest.approx([CLASSIC_RULES[0, i, j] * 0.1, CLASSIC_RULES[1, i, j] * 0.01,
                               CLASSIC_RULES[2, i, j] * 0.02], abs=1e-12)


def test_fuzzy_increments_interpolate_and_saturate():
    c = FuzzyPID(e_range_kmh=3.0, ec_range_kmhs=3.0, dkp=0.3, dki=0.03, dkd=0.06)
    p = c.params()
    rules = SYMMETRIC_RULES
    # halfway between e = NS and e = ZO at ec = ZO: the mean of the two rules
    d = fuzzy_increments(p, -0.5, 0.0)
    assert d[0] == pytest.approx(0.5 * (rules[0, 2, 3] + rules[0, 3, 3]) * 0.1)
    # beyond the universe the outer term holds
    assert fuzzy_increments(p, 50.0, -50.0) == pytest.approx(fuzzy_increments(p, 3.0, -3.0))
    # every increment within its scale
    for e in np.linspace(-5, 5, 21):
        for ec in np.linspace(-5, 5, 21):
            d = fuzzy_increments(p, e, ec)
            assert abs(d[0]) <= 0.3 + 1e-12 and abs(d[1]) <= 0.03 + 1e-12 and abs(d[2]) <= 0.06 + 1e-12


def test_symmetric_rules_are_symmetric_and_keep_the_classic_half():
    assert np.array_equal(SYMMETRIC_RULES, SYMMETRIC_RULES[:, ::-1, ::-1])
    assert np.array_equal(SYMMETRIC_RULES[:, :3, :], CLASSIC_RULES[:, :3, :])
    # the printed Kp and Ki tables are anti-symmetric in sign: the reason for the symmetric default
    for g in (0, 1):
        assert np.array_equal(np.sign(CLASSIC_RULES[g]), -np.sign(CLASSIC_RULES[g, ::-1, ::-1]))


def test_pid_output_and_anti_windup():
    p = PID(kp=0.5, ki=0.1, kd=0.0).params()
    state = np.zeros(4)
    assert controller_command(1, p, state, 1.0, 1.0) == pytest.approx(0.5 + 0.1 * 1.0)
    assert controller_command(1, p, state, 1.0, 1.0) == pytest.approx(0.5 + 0.1 * 2.0)
    for _ in range(100):  # a long saturating error must not wind the integral up
        assert controller_command(1, p, state, 10.0, 1.0) == 1.0
    assert state[1] == pytest.approx(2.0)
    assert controller_command(1, p, state, -1.0, 1.0) == pytest.approx(-0.5 + 0.1 * 1.0)


def test_hysteresis_states():
    p = Hysteresis(2.0, 4.0, overspeed_kmh=1.0, brake_fraction=0.4).params()
    state = np.array([1.0, 0.0, 0.0, 0.0])  # coming from traction
    seq = [(3.0, 1.0), (1.9, 0.0), (3.0, 0.0), (4.1, 1.0), (3.0, 1.0), (0.5, 0.0), (-1.1, -0.4),
           (-0.5, -0.4), (0.0, 0.0), (3.9, 0.0), (4.5, 1.0)]
    for e, expected in seq:
        assert controller_command(0, p, state, e, 0.2) == expected, (e, expected)


@pytest.mark.parametrize("make, field, value", [
    (lambda: Hysteresis(2.0, 2.0), "a_kmh", 2.0),
    (lambda: Hysteresis(3.0, 2.0), "a_kmh", 3.0),
    (lambda: Hysteresis(-1.0, 2.0), "a_kmh", -1.0),
    (lambda: Hysteresis(1.0, math.nan), "b_kmh", "nan"),
    (lambda: Hysteresis(1.0, 2.0, brake_fraction=1.5), "brake_fraction", 1.5),
    (lambda: Hysteresis(1.0, 2.0, brake_fraction=0.0), "brake_fraction", 0.0),
    (lambda: PID(kp=-0.1), "kp", -0.1),
    (lambda: PID(ki=math.nan), "ki", "nan"),
    (lambda: PID(kd=math.inf), "kd", "inf"),
    (lambda: PID(kp="1"), "kp", "'1'"),
    (lambda: FuzzyPID(dkp=-0.1), "dkp", -0.1),
    (lambda: FuzzyPID(e_range_kmh=0.0), "e_range_kmh", 0.0),
    (lambda: FuzzyPID(ec_range_kmhs=math.nan), "ec_range_kmhs", "nan"),
    (lambda: FuzzyPID(rules=np.zeros((3, 7, 6))), "rules", "(3, 7, 6)"),
    (lambda: FuzzyPID(rules=np.full((3, 7, 7), 4.0)), "rules", "4.0"),
])
def test_bad_controller_parameters(make, field, value):
    with pytest.raises(ValueError, match=field) as info:
        make()
    assert str(value) in str(info.value)


@pytest.mark.parametrize("period", [0.0, -0.2, math.nan, math.inf, "0.2"])
def test_bad_control_period(yizhuang, yizhuang_cruise, period):
    with pytest.raises(ValueError, match="control_period_s") as info:
        track(yizhuang, yizhuang_cruise, PID(), control_period_s=period)
    assert str(period) in str(info.value) or repr(period) in str(info.value)


def test_bad_reference(yizhuang, yizhuang_cruise):
    speeds = yizhuang_cruise.speed_ms.copy()
    speeds[40] = math.nan
    bad = dataclasses.replace(yizhuang_cruise, speed_ms=speeds)
    with pytest.raises(ValueError, match=r"reference.speed_ms\[40\] = nan"):
        track(yizhuang, bad, PID())
    speeds = yizhuang_cruise.speed_ms.copy()
    speeds[7] = -1.0
    with pytest.raises(ValueError, match=r"reference.speed_ms\[7\] = -1.0"):
        track(yizhuang, dataclasses.replace(yizhuang_cruise, speed_ms=speeds), PID())
    x = yizhuang_cruise.position_m.copy()
    x[10] = 5.0
    with pytest.raises(ValueError, match=r"reference.position_m\[10\] = 5.0"):
        track(yizhuang, dataclasses.replace(yizhuang_cruise, position_m=x), PID())
    with pytest.raises(ValueError, match="reference"):
        track(yizhuang, yizhuang_cruise.speed_ms, PID())


def test_bad_controller_object(yizhuang, yizhuang_cruise):
    with pytest.raises(ValueError, match="controller = 'pid'"):
        track(yizhuang, yizhuang_cruise, "pid")


def test_bad_programs_shape(yizhuang):
    with pytest.raises(ValueError, match=r"\(N, rows, 3\)"):
        Tracker(yizhuang, PID()).run_batch(np.zeros((4, 3)))


def test_controllers_are_frozen_and_hashable():
    c = Hysteresis(2.0, 4.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.a_kmh = 1.0
    assert hash(c) == hash(Hysteresis(2.0, 4.0)) and PID() == PID()
    assert FuzzyPID() == FuzzyPID() and hash(FuzzyPID()) == hash(FuzzyPID())


def test_make_controller_builds_each_controller_by_name_and_names_bad_input():
    from pymoo_rail.control import make_controller

    assert make_controller("hysteresis", a_kmh=2, b_kmh=5) == Hysteresis(2.0, 5.0)
    assert make_controller("pid", kp=0.3) == PID(kp=0.3)
    assert make_controller("fuzzy_pid").name == FuzzyPID().name
    with pytest.raises(ValueError, match="controller = 'pi'"):
        make_controller("pi")
    with pytest.raises(ValueError, match="controller = 'pid'.*kq"):
        make_controller("pid", kq=1.0)
    with pytest.raises(ValueError, match="'b_kmh' = 'x'"):  # the controller's own field check
        make_controller("hysteresis", b_kmh="x")
