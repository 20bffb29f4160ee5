import math

import numpy as np
import pytest

from pymoo_rail.model import CaseError, DavisResistance, ForceCurve
from pymoo_rail.sim.physics import curve_force


def test_yizhuang_traction_matches_eq_5_1(yizhuang):
    f = yizhuang.train.traction
    # eq. 5-1 by hand: 203 kN up to 51.5 km/h, then the cubic
    v = 60.0
    cubic = -0.002032 * v**3 + 0.4928 * v**2 - 42.13 * v + 1343
    assert f.force_kn([0.0, 30.0, 51.5])[0] == 203.0
    assert f.force_kn(v)[0] == pytest.approx(cubic, rel=1e-12)
    assert cubic == pytest.approx(150.368, abs=1e-3)


def test_yizhuang_braking_matches_eq_5_2(yizhuang):
    b = yizhuang.train.braking
    assert b.force_kn(50.0)[0] == 166.0
    assert b.force_kn(80.0)[0] == pytest.approx(0.134 * 6400 - 25.07 * 80 + 1300)


@pytest.mark.parametrize("curve", [
    ForceCurve(segments=((51.5, (203.0,)), (80.0, (1343.0, -42.13, 0.4928, -0.002032)))),
    ForceCurve(table=((0.0, 300.0), (100.0, 250.0), (200.0, 120.0))),
    ForceCurve(max_force_kn=300.0, max_power_kw=8800.0),
    ForceCurve(table=((0.0, 300.0), (150.0, 200.0)), max_power_kw=5000.0),
])
def test_kernel_curve_equals_reference(curve):
    breaks, coefs, fmax, pmax = curve.piecewise_si()
    for v_kmh in np.linspace(0.0, 250.0, 77):
        ref = curve.force_kn(v_kmh)[0] * 1000.0
        got = curve_force(v_kmh / 3.6, breaks, coefs, fmax, pmax)
        assert got == pytest.approx(ref, rel=1e-9, abs=1e-6)


def test_power_cap_is_hyperbolic():
    c = ForceCurve(max_force_kn=300.0, max_power_kw=8800.0)
    # above the corner speed 8800/300 m/s the force is P / v
    v_ms = 50.0
    assert c.force_kn(v_ms * 3.6)[0] == pytest.approx(8800.0 / v_ms)


def test_curve_needs_exactly_one_form():
    with pytest.raises(CaseError, match="exactly one form"):
        ForceCurve()
    with pytest.raises(CaseError, match="exactly one form"):
        ForceCurve(max_force_kn=1.0, table=((0.0, 1.0),))


def test_table_must_increase():
    with pytest.raises(CaseError, match=r"table\[2\]"):
        ForceCurve(table=((0.0, 1.0), (10.0, 1.0), (5.0, 1.0)))


def test_davis_units():
    m = 100_000.0
    kn = DavisResistance(2.0, 0.1, 0.01, "kN", "kmh")
    a, b, c = kn.coefficients_si(m)
    v_ms = 20.0
    assert a + b * v_ms + c * v_ms**2 == pytest.approx(1000.0 * (2.0 + 0.1 * 72.0 + 0.01 * 72.0**2))
    per_weight = DavisResistance(2.0, 0.0, 0.0, "N/kN", "ms")
    a, _, _ = per_weight.coefficients_si(m)
    assert a == pytest.approx(2.0 * m * 9.81 / 1000.0)


@pytest.mark.parametrize("field,value", [("unit", "kN/t"), ("speed_unit", "mph")])
def test_davis_rejects_unknown_units(field, value):
    kwargs = dict(a=1.0, b=0.0, c=0.0, unit="kN", speed_unit="kmh")
    kwargs[field] = value
    with pytest.raises(CaseError, match=f"resistance.{field}.*{value}"):
        DavisResistance(**kwargs)


def test_davis_rejects_nan():
    with pytest.raises(CaseError, match="resistance.a"):
        DavisResistance(math.nan, 0.0, 0.0, "kN", "kmh")
