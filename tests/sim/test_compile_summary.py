"""sim.jit.CompileProfile.summary: compile time by module, stage and function, and repeated signatures."""

from __future__ import annotations

from pymoo_rail.sim.jit import CompileProfile


def test_summary_adds_up_stages_modules_and_names_repeated_signatures():
    profile = CompileProfile()
    profile.seconds = {("pkg.a.f", "NativeLowering"): 2.0, ("pkg.a.f", "other"): 0.1,
                       ("pkg.b.g", "NativeLowering"): 0.5, ("pkg.b.g", "InlineInlinables"): 1.0}
    profile.compiles = {"pkg.a.f": 2, "pkg.b.g": 1}
    profile.signatures = {"pkg.a.f": ["(float64, int64)", "(float64, float32)"], "pkg.b.g": ["(int64,)"]}
    text = profile.summary(top=1, signatures=True)
    lines = text.splitlines()
    assert lines[0] == "compile (CPU) 3.6 s"
    assert "      2.1 s  pkg.a" in lines and "      1.5 s  pkg.b" in lines
    assert "      2.5 s  NativeLowering" in lines
    # only the dearest function, with its stages of 0.2 s and more
    assert "      2.1  x2  pkg.a.f: NativeLowering 2.0" in lines and not any("pkg.b.g:" in line for line in lines[:-2])
    assert lines[-1].startswith("  pkg.a.f: ") and "int64" in lines[-1] and "float32" in lines[-1]
    assert "more than one signature" not in profile.summary()
