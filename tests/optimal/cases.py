"""Synthetic cases for the solver tests (built with the shared ``make_case`` factory)."""

from tests.conftest import make_case


def level_case(**train):
    """5 km of level track with Davis resistance: long enough for a hold phase at 230-350 s."""
    return make_case(train={"resistance": {"a": 2.0, "b": 0.1, "c": 0.03, "unit": "kN", "speed_unit": "ms"},
                            **train},
                     line={"length_m": 5000.0, "gradients": [[0.0, 5000.0, 0.0]],
                           "speed_limits": [[0.0, 5000.0, 100.0]]})


def hilly_case(**train):
    """Everything the model has: climb and descent, three limits, a neutral section, a power cap,
    acceleration caps, rotating mass, traction efficiency, regeneration with caps and a cut-off,
    auxiliary power."""
    spec = {"mass_t": 200.0, "length_m": 120.0, "max_speed_kmh": 90.0, "max_accel_ms2": 0.9,
            "max_decel_ms2": 1.0, "rotary_factor": 0.08, "traction_efficiency": 0.85, "regen_efficiency": 0.7,
            "regen_min_speed_kmh": 8.0, "aux_power_kw": 60.0,
            "resistance": {"a": 2.0, "b": 0.06, "c": 0.0018, "unit": "kN", "speed_unit": "kmh"},
            "traction": {"max_force_kn": 260.0, "max_power_kw": 2500.0},
            "braking": {"max_force_kn": 240.0, "regen_max_force_kn": 180.0, "regen_max_power_kw": 3000.0}}
    spec.update(train)
    return make_case(
        train=spec,
        line={"length_m": 3000.0,
              "gradients": [[0.0, 600.0, 0.0], [600.0, 1300.0, 12.0], [1300.0, 2100.0, -15.0], [2100.0, 3000.0, 3.0]],
              "speed_limits": [[0.0, 300.0, 60.0], [300.0, 2500.0, 90.0], [2500.0, 3000.0, 70.0]],
              "neutral_sections": [[1500.0, 1600.0]]})
