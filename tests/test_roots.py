"""spur_cad.geometry.roots against scipy.optimize, its independent reference (the port must give the same bits):
brentq's root, function calls and iterations, and minimize_scalar(method="bounded")'s x, fun and evaluations, on
generic functions (polynomials, steep, flat near the root, roots at the bracket ends, errors) and on every solve
the project itself makes while building undercut, internal and modified profiles and generating flank rolls.
A reference run must not import scipy.optimize (0.4 s and 50 MB of imports)."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq as scipy_brentq
from scipy.optimize import minimize_scalar

from spur_cad.geometry import roots
from spur_cad.geometry.involute import involute_function
from spur_cad.geometry.roots import brentq_result, minimize_bounded

ROOT = Path(__file__).resolve().parents[1]
SCIPY_RTOL = 4 * np.finfo(float).eps
TOLERANCES = [(2e-12, SCIPY_RTOL), (1e-14, 1e-14), (1e-15, 1e-15), (1e-13, SCIPY_RTOL)]

INVOLUTE_20 = involute_function(math.radians(20.0))
FUNCTIONS = {  # name: (f, a, b)
    "inverse involute, 20 deg": (lambda a: involute_function(a) - INVOLUTE_20, 0.0, 1.5),
    "inverse involute, tiny value": (lambda a: involute_function(a) - 1e-9, 1e-6, 1.0),
    "cubic": (lambda x: x ** 3 - 2.0 * x - 5.0, 2.0, 3.0),
    "reversed bracket": (lambda x: x ** 3 - 2.0 * x - 5.0, 3.0, 2.0),
    "triple root, flat near it (100-150 iterations)": (lambda x: (x - 0.5) ** 3, 0.1, 1.3),
    "fifth-order root": (lambda x: (x - 0.4) ** 5, 0.0, 1.3),
    "steep": (lambda x: math.tanh(50.0 * (x - 0.3)), 0.0, 1.0),
    "step": (lambda x: -1e-200 if x < 0.5 else 1e-200, 0.0, 1.0),
    "exponential, wide bracket": (lambda x: math.exp(x) - 2.0, -10.0, 10.0),
    "tiny values": (lambda x: 1e-200 * (x - 0.3), 0.0, 1.0),
    "infinite below": (lambda x: math.inf if x < 0.2 else 0.5 - x, 0.0, 1.0),
    "cosine": (lambda x: math.cos(x) - x, 0.0, 1.0),
}


@pytest.mark.parametrize("xtol, rtol", TOLERANCES)
@pytest.mark.parametrize("name", FUNCTIONS)
def test_brentq_gives_scipys_bits_after_as_many_iterations(name, xtol, rtol):
    f, a, b = FUNCTIONS[name]
    expected, info = scipy_brentq(f, a, b, xtol=xtol, rtol=rtol, maxiter=1000, full_output=True)
    ours = brentq_result(f, a, b, xtol=xtol, rtol=rtol, maxiter=1000)
    assert ours.root == expected
    assert (ours.iterations, ours.function_calls) == (info.iterations, info.function_calls)
    assert roots.brentq(f, a, b, xtol=xtol, rtol=rtol, maxiter=1000) == expected


@pytest.mark.parametrize("f, a, b", [(lambda x: x, 0.0, 1.0), (lambda x: x - 1.0, 0.0, 1.0),
                                     (lambda x: -0.0 if x == 0 else 1.0, 0.0, 1.0)])
def test_a_root_at_a_bracket_end_is_that_end(f, a, b):
    """Returned after the two end values, as scipy does (scipy leaves its iteration count unset there)."""
    expected, info = scipy_brentq(f, a, b, full_output=True)
    ours = brentq_result(f, a, b)
    assert ours.root == expected and ours.function_calls == info.function_calls == 2 and ours.iterations == 0


@pytest.mark.parametrize("f, a, b, kwargs", [
    (lambda x: 1.0, 0.0, 1.0, {}),  # same sign
    (lambda x: 1e-200, 0.0, 1.0, {}),  # same sign, the product underflows to 0
    (lambda x: -x - 1.0, 0.0, 1.0, {}),
    (lambda x: math.nan, 0.0, 1.0, {}),
    (lambda x: x - 0.3, 0.0, 1.0, {"xtol": 0.0}),
    (lambda x: x - 0.3, 0.0, 1.0, {"rtol": 1e-16}),
    (lambda x: (x - 0.5) ** 9, 0.0, 1.3, {}),  # flat near its root: does not converge in 100 iterations
    (lambda x: math.cos(x) - x, 0.0, 1.0, {"maxiter": 3}),
])
def test_brentq_refuses_what_scipy_refuses_with_the_same_error(f, a, b, kwargs):
    with pytest.raises((ValueError, RuntimeError)) as expected:
        scipy_brentq(f, a, b, **kwargs)
    with pytest.raises(expected.type, match="^" + expected.value.args[0].replace("(", r"\(").replace(")", r"\)")):
        brentq_result(f, a, b, **kwargs)


BOUNDED = {  # name: (f, lower, upper)
    "parabola": (lambda x: (x - 0.3) ** 2, 0.0, 1.0),
    "sine": (math.sin, 0.0, 6.0),
    "kink": (lambda x: abs(x - 0.123), 0.0, 1.0),
    "constant": (lambda x: 0.0, 0.0, 1.0),
    "minimum at the upper bound": (lambda x: -x, 0.0, 1.0),
    "wavy": (lambda x: math.cos(3.0 * x) + 0.1 * x, -2.0, 3.0),
    "quartic, narrow": (lambda x: (x - 1.0) ** 4, 0.999, 1.002),
}


@pytest.mark.parametrize("xatol", [1e-5, 1e-12])
@pytest.mark.parametrize("name", BOUNDED)
def test_minimize_bounded_gives_scipys_bits(name, xatol):
    f, lower, upper = BOUNDED[name]
    expected = minimize_scalar(f, bounds=(lower, upper), method="bounded", options={"xatol": xatol})
    ours = minimize_bounded(f, lower, upper, xatol=xatol)
    assert (ours.x, ours.fun, ours.nfev, ours.status) == (expected.x, expected.fun, expected.nfev, expected.status)


def test_minimize_bounded_stops_at_maxiter_as_scipy_does():
    f = BOUNDED["wavy"][0]
    expected = minimize_scalar(f, bounds=(-2.0, 3.0), method="bounded", options={"xatol": 1e-12, "maxiter": 5})
    ours = minimize_bounded(f, -2.0, 3.0, xatol=1e-12, maxiter=5)
    assert expected.status == ours.status == 1 and (ours.x, ours.fun, ours.nfev) == (expected.x, expected.fun, 5)


@pytest.mark.parametrize("lower, upper", [(1.0, 0.0), (0.0, math.inf)])
def test_minimize_bounded_refuses_bad_bounds(lower, upper):
    with pytest.raises(ValueError):
        minimize_scalar(math.sin, bounds=(lower, upper), method="bounded")
    with pytest.raises(ValueError):
        minimize_bounded(math.sin, lower, upper)


CALL_SITES = ["spur_cad.geometry.profile", "spur_cad.geometry.internal", "spur_cad.geometry.modifications",
              "spur_cad.cam.strategies.generating_geometry", "spur_cad.cam.strategies.generating_flat"]


def _project_solves(monkeypatch) -> tuple[list, list]:
    """Every brentq / minimize_bounded call the project makes while building the test gears' profiles (undercut,
    internal, modified) and a generating gear's flank rolls: (f, a, b, keyword arguments) each."""
    import importlib

    from spur_cad.cam.strategies.generating import flank_rolls
    from spur_cad.geometry.internal import InternalGearSpec
    from spur_cad.geometry.sampling import sample_profile
    from spur_cad.job import parse_job
    from spur_cad.pipeline import job_profile_csv
    from tests.gears import GEAR_CASES, spec_of

    root_calls, minimum_calls = [], []

    def recording_brentq(f, a, b, **kwargs):
        root_calls.append((f, a, b, kwargs))
        return roots.brentq(f, a, b, **kwargs)

    def recording_minimize(f, lower, upper, **kwargs):
        minimum_calls.append((f, lower, upper, kwargs))
        return roots.minimize_bounded(f, lower, upper, **kwargs)

    for name in CALL_SITES:
        module = importlib.import_module(name)
        monkeypatch.setattr(module, "brentq", recording_brentq)
        if hasattr(module, "minimize_bounded"):
            monkeypatch.setattr(module, "minimize_bounded", recording_minimize)
    for name in GEAR_CASES:
        spec_of(name).tooth_space_profile()
    InternalGearSpec(teeth=60, module_mm=2.0, addendum_coefficient=0.9, rack_tip_radius_mm=0.4,
                     shaper_cutter_teeth=20, rim_outer_diameter_mm=140.0, face_width_mm=10.0).tooth_space_profile()
    job = parse_job("[gear]\nteeth = 23\nmodule_mm = 4.0\nface_width_mm = 20\nrack_tip_radius_mm = 1.52\n"
                    "[gear.modifications]\ntip_relief_um = 15\ntip_relief_start_diameter_mm = 98\n", "f.toml")
    job_profile_csv(job, sample_profile(job.gear.tooth_space_profile(), 0.001))
    flank_rolls(spec_of("reference_z23_m4"), 0.005)
    monkeypatch.undo()  # replaying a recorded function must not record its inner solves
    return root_calls, minimum_calls


def test_the_projects_own_solves_give_scipys_bits(monkeypatch):
    root_calls, minimum_calls = _project_solves(monkeypatch)
    sites = {f.__code__.co_filename.rsplit("/", 1)[-1] for f, *_ in root_calls}
    assert sites >= {"profile.py", "internal.py", "modifications.py", "generating_geometry.py",
                     "generating_flat.py"}, sites
    assert len(minimum_calls) >= 2  # the undercut cases' depth
    for f, a, b, kwargs in root_calls:
        expected, info = scipy_brentq(f, a, b, full_output=True, **kwargs)
        ours = brentq_result(f, a, b, **kwargs)
        assert (ours.root, ours.function_calls) == (expected, info.function_calls), (f, a, b, kwargs)
        if ours.iterations:  # scipy leaves its count unset for a root at a bracket end
            assert ours.iterations == info.iterations
    for f, lower, upper, kwargs in minimum_calls:
        expected = minimize_scalar(f, bounds=(lower, upper), method="bounded", options=kwargs)
        ours = minimize_bounded(f, lower, upper, **kwargs)
        assert (ours.x, ours.fun, ours.nfev) == (expected.x, expected.fun, expected.nfev)


SCRIPT = """
import json, sys
from spur_cad.job import load_job
from spur_cad.pipeline import run_job
run_job(load_job("resources/examples/reference_gear.toml"))
json.dump(sorted(name for name in sys.modules if name.startswith("scipy")), sys.stdout)
"""


@pytest.mark.slow  # a whole run in a subprocess (8 s)
def test_a_reference_run_does_not_import_scipy_optimize(tmp_path):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = subprocess.run([sys.executable, "-c", SCRIPT], cwd=ROOT, env=env, capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    imported = json.loads(done.stdout)
    assert not [name for name in imported if name.startswith("scipy.optimize")], imported
