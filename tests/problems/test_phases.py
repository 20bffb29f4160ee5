"""The kinematic four-phase model of Meng et al. (2017): closed form, binary genes, constraints."""

import math
import warnings

import numpy as np
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.problems import ConstantObjectiveWarning, KinematicPhasesProblem, phase_runs
from pymoo_rail.problems.phases import decode_bits, encode_bits, exact_stop_coast_m

A = (1.0, 0.0, -0.033, -1.1)


def _problem(**kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConstantObjectiveWarning)
        return KinematicPhasesProblem(load_case("metro-a"), **kwargs)


def test_closed_form_run():
    r = phase_runs(np.array([[200.0, 100.0, 300.0]]), A, 332e3)
    v1 = math.sqrt(2 * 200.0)
    v3 = math.sqrt(v1 ** 2 - 2 * 0.033 * 300.0)
    np.testing.assert_allclose(r.speed_end_ms[0], [v1, v1, v3, 0.0])
    np.testing.assert_allclose(r.duration_s[0], [v1, 100.0 / v1, (v1 - v3) / 0.033, v3 / 1.1])
    assert r.length_m[0, 3] == pytest.approx(v3 ** 2 / 2.2)
    assert r.energy_index_kwh[0] == pytest.approx(332e3 * 1.0 * 200.0 / 3.6e6)
    assert r.comfort_ms2[0] == pytest.approx(1.0 + 1.0 + 0.033 + (1.1 - 0.033) + 1.1)


def test_a_skipped_phase_leaves_the_comfort_index():
    r = phase_runs(np.array([[200.0, 0.0, 300.0]]), A, 332e3)
    assert r.comfort_ms2[0] == pytest.approx(1.0 + 1.033 + 1.067 + 1.1)


def test_the_papers_lengths_break_its_own_limit():
    # Meng et al. (2017) table 3: 262.37 m at 1.0 m/s^2 reaches 82.5 km/h (> 80), braking from 80.5 km/h
    # at 1.1 m/s^2 needs 227.4 m (printed: 198.97 m)
    p = _problem(weights=(0.1, 0.2, 0.4, 0.3), binary=False)
    out = p.evaluate(np.array([[262.37, 169.15, 369.69]]), return_as_dictionary=True)
    assert out["peak_speed_kmh"][0] == pytest.approx(3.6 * math.sqrt(2 * 262.37))
    assert out["G"][0].max() > 0
    assert out["phase_lengths_m"][0, 3] == pytest.approx(227.42, abs=0.01)


def test_binary_genes_round_trip():
    values = np.array([[0.0, 500.0, 1000.0], [262.37, 169.15, 369.69]])
    bits = encode_bits(values, 16, 1000.0)
    assert bits.shape == (2, 48) and bits.dtype == bool
    np.testing.assert_allclose(decode_bits(bits, 3, 1000.0), values, atol=1000.0 / 65535 / 2 + 1e-12)
    p = _problem()
    assert p.n_var == 48 and p.vtype is bool
    with pytest.raises(ValueError, match="0/1"):
        decode_bits(np.full((1, 48), 2), 3, 1000.0)


def test_exact_stop_coast_and_constraints():
    p = _problem(weights=(0.1, 0.2, 0.4, 0.3), binary=False)
    coast = exact_stop_coast_m(p, np.array([189.0]), np.array([584.0]))
    out = p.evaluate(np.array([[189.0, 584.0, coast[0]]]), return_as_dictionary=True)
    assert out["stop_position_m"][0] == pytest.approx(1000.0, abs=1e-6)
    assert out["G"][0].max() <= 0
    # a 1 m traction phase lasts 1.4 s < the 2 s minimum
    out = p.evaluate(np.array([[1.0, 500.0, 100.0]]), return_as_dictionary=True)
    assert out["G"][0, 0] > 0


def test_jerk_is_named_constant_and_bad_input():
    with pytest.warns(ConstantObjectiveWarning, match="accel_variation"):
        KinematicPhasesProblem(load_case("metro-a"))
    with pytest.warns(ConstantObjectiveWarning, match="jerk"):  # the paper's name, an alias
        KinematicPhasesProblem(load_case("metro-a"), objectives=("energy", "jerk"))
    with pytest.raises(ValueError, match="accelerations_ms2"):
        _problem(accelerations_ms2=(1.0, 0.0, -0.033, 0.5))
    with pytest.raises(ValueError, match="weights"):
        _problem(weights=(0.1, 0.2))
    with pytest.raises(ValueError, match="n_bits"):
        _problem(n_bits=1)


def test_study_registry_builds_it():
    from pymoo_rail.experiments import build_problem, problem

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConstantObjectiveWarning)
        p = build_problem(problem("kinematic_phases", weights=[0.1, 0.2, 0.4, 0.3]))
    assert isinstance(p, KinematicPhasesProblem) and p.n_obj == 1
