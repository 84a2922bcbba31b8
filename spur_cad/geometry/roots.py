"""Scalar bracketed root finding and bounded scalar minimisation in plain Python, so that a run does not import
scipy.optimize (0.4 s and 50 MB of imports for two scalar solvers).

`brentq` follows scipy's `scipy/optimize/Zeros/brentq.c` (Brent's method as written by Charles Harris) and
`minimize_bounded` follows scipy's `_minimize_scalar_bounded` (`minimize_scalar(method="bounded")`, i.e. `fminbound`):
the same steps, the same arithmetic in the same order and the same stopping rules, so that on the same function
they return bit-identical results after the same number of iterations (tests/test_roots.py compares them with
scipy's). Only the options spur_cad uses are supported: xtol, rtol, maxiter for the root; bounds and xatol for the
minimum.
"""

# The algorithms below are ported from SciPy, which is distributed under the BSD 3-clause licence:
#   Copyright (c) 2001-2002 Enthought, Inc. 2003, SciPy Developers. All rights reserved.
#   Redistribution and use in source and binary forms, with or without modification, are permitted provided that
#   (1) redistributions of source code retain the copyright notice, this list of conditions and the following
#   disclaimer; (2) redistributions in binary form reproduce them in the documentation and/or other materials
#   provided with the distribution; (3) neither the name of the copyright holder nor the names of its contributors
#   may be used to endorse or promote products derived from this software without specific prior written
#   permission. THIS SOFTWARE IS PROVIDED BY THE COPYRIGHT HOLDERS AND CONTRIBUTORS "AS IS" AND ANY EXPRESS OR
#   IMPLIED WARRANTIES, INCLUDING, BUT NOT LIMITED TO, THE IMPLIED WARRANTIES OF MERCHANTABILITY AND FITNESS FOR A
#   PARTICULAR PURPOSE ARE DISCLAIMED. IN NO EVENT SHALL THE COPYRIGHT OWNER OR CONTRIBUTORS BE LIABLE FOR ANY
#   DIRECT, INDIRECT, INCIDENTAL, SPECIAL, EXEMPLARY, OR CONSEQUENTIAL DAMAGES ARISING IN ANY WAY OUT OF THE USE OF
#   THIS SOFTWARE, EVEN IF ADVISED OF THE POSSIBILITY OF SUCH DAMAGE.

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from typing import NamedTuple

BRENTQ_XTOL = 2e-12  # scipy's defaults for brentq
BRENTQ_RTOL_MIN = 4 * sys.float_info.epsilon  # also the smallest rtol scipy accepts
BRENTQ_MAXITER = 100
SQRT_EPS = math.sqrt(2.2e-16)  # _minimize_scalar_bounded's constants, computed as it computes them
GOLDEN_MEAN = 0.5 * (3.0 - math.sqrt(5.0))


class RootResult(NamedTuple):
    """A root found by `brentq_result`, with scipy's counts (RootResults.iterations and .function_calls)."""

    root: float
    iterations: int
    function_calls: int


class BoundedMinimum(NamedTuple):
    """The result of `minimize_bounded`, as scipy's OptimizeResult: x, fun, nfev and status (0 converged,
    1 maxiter function evaluations reached, 2 a NaN met)."""

    x: float
    fun: float
    nfev: int
    status: int


def _c_divide(numerator: float, denominator: float) -> float:
    """numerator / denominator with C's IEEE result for a zero denominator (inf or NaN) instead of an exception."""
    if denominator != 0.0:
        return numerator / denominator
    if math.isnan(numerator) or numerator == 0.0:
        return math.nan
    return math.copysign(math.inf, numerator) * math.copysign(1.0, denominator)


def _value(f: Callable[[float], float], x: float) -> float:
    """f(x) as a float; a NaN is refused as scipy refuses it (ValueError)."""
    fx = float(f(x))
    if math.isnan(fx):
        raise ValueError(f"The function value at x={x} is NaN; solver cannot continue.")
    return fx


def _brent_steps(xpre: float, fpre: float, xcur: float, fcur: float, xblk: float, fblk: float,
                 spre: float, scur: float, sbis: float, delta: float) -> tuple[float, float]:
    """brentq.c's choice of the next step: inverse quadratic (or linear) interpolation when it is short enough,
    bisection otherwise. Returns the new (spre, scur)."""
    if abs(spre) > delta and abs(fcur) < abs(fpre):
        if xpre == xblk:  # interpolate
            stry = _c_divide(-fcur * (xcur - xpre), fcur - fpre)
        else:  # extrapolate
            dpre = _c_divide(fpre - fcur, xpre - xcur)
            dblk = _c_divide(fblk - fcur, xblk - xcur)
            stry = _c_divide(-fcur * (fblk * dblk - fpre * dpre), dblk * dpre * (fblk - fpre))
        limit = 3 * abs(sbis) - delta
        if 2 * abs(stry) < (abs(spre) if abs(spre) < limit else limit):  # good short step
            return scur, stry
    return sbis, sbis  # bisect


def brentq_result(f: Callable[[float], float], a: float, b: float, xtol: float = BRENTQ_XTOL,
                  rtol: float = BRENTQ_RTOL_MIN, maxiter: int = BRENTQ_MAXITER) -> RootResult:
    """A root of f in [a, b] by Brent's method, as scipy.optimize.brentq(..., full_output=True) finds it.

    Raises ValueError when f(a) and f(b) have the same sign, f returns NaN or a tolerance is out of scipy's range,
    and RuntimeError when maxiter iterations do not converge."""
    if xtol <= 0:
        raise ValueError(f"xtol too small ({xtol:g} <= 0)")
    if rtol < BRENTQ_RTOL_MIN:
        raise ValueError(f"rtol too small ({rtol:g} < {BRENTQ_RTOL_MIN:g})")
    if maxiter < 0:
        raise ValueError("maxiter should be > 0")
    xpre, xcur = float(a), float(b)
    fpre, fcur = _value(f, xpre), _value(f, xcur)
    calls = 2
    if fpre == 0:
        return RootResult(xpre, 0, calls)
    if fcur == 0:
        return RootResult(xcur, 0, calls)
    if math.copysign(1.0, fpre) == math.copysign(1.0, fcur):  # signbit: no product to underflow
        raise ValueError("f(a) and f(b) must have different signs")
    xtol, rtol = float(xtol), float(rtol)  # C doubles, as scipy passes them
    xblk = fblk = spre = scur = 0.0
    for iteration in range(1, maxiter + 1):
        if fpre != 0 and fcur != 0 and math.copysign(1.0, fpre) != math.copysign(1.0, fcur):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (xtol + rtol * abs(xcur)) / 2
        sbis = (xblk - xcur) / 2
        if fcur == 0 or abs(sbis) < delta:
            return RootResult(xcur, iteration, calls)
        spre, scur = _brent_steps(xpre, fpre, xcur, fcur, xblk, fblk, spre, scur, sbis, delta)
        xpre, fpre = xcur, fcur
        if abs(scur) > delta:
            xcur += scur
        else:
            xcur += delta if sbis > 0 else -delta
        fcur = _value(f, xcur)
        calls += 1
    raise RuntimeError(f"Failed to converge after {maxiter} iterations.")


def brentq(f: Callable[[float], float], a: float, b: float, xtol: float = BRENTQ_XTOL,
           rtol: float = BRENTQ_RTOL_MIN, maxiter: int = BRENTQ_MAXITER) -> float:
    """A root of f in [a, b], bit-identical to scipy.optimize.brentq's (see `brentq_result`)."""
    return brentq_result(f, a, b, xtol, rtol, maxiter).root


def _sign_or_one(value: float) -> float:
    """np.sign(value) + (value == 0): +1 or -1 by the sign, +1 for zero, NaN for NaN."""
    if math.isnan(value):
        return math.nan
    return -1.0 if value < 0 else 1.0


def _nan_max(first: float, second: float) -> float:
    """np.maximum of two floats: NaN if either is."""
    if math.isnan(first) or math.isnan(second):
        return math.nan
    return first if first >= second else second


def _parabolic_step(xf: float, fx: float, nfc: float, fnfc: float, fulc: float, ffulc: float,
                    a: float, b: float, e: float, rat: float) -> tuple[float, float, bool]:
    """_minimize_scalar_bounded's parabola through the three best points: returns (rat, e, accepted)."""
    r = (xf - nfc) * (fx - ffulc)
    q = (xf - fulc) * (fx - fnfc)
    p = (xf - fulc) * q - (xf - nfc) * r
    q = 2.0 * (q - r)
    if q > 0.0:
        p = -p
    q = abs(q)
    r = e
    e = rat
    if abs(p) < abs(0.5 * q * r) and p > q * (a - xf) and p < q * (b - xf):
        return (p + 0.0) / q, e, True
    return rat, e, False


def _bounded_step(xf: float, fx: float, nfc: float, fnfc: float, fulc: float, ffulc: float, a: float, b: float,
                  e: float, rat: float, tol1: float) -> tuple[float, float]:
    """_minimize_scalar_bounded's next step: the parabola's when acceptable, golden section otherwise.
    Returns (rat, e)."""
    xm = 0.5 * (a + b)
    if abs(e) > tol1:  # try a parabolic fit
        rat, e, accepted = _parabolic_step(xf, fx, nfc, fnfc, fulc, ffulc, a, b, e, rat)
        if accepted:
            if ((xf + rat) - a) < 2.0 * tol1 or (b - (xf + rat)) < 2.0 * tol1:
                rat = tol1 * _sign_or_one(xm - xf)
            return rat, e
    e = (a - xf) if xf >= xm else (b - xf)  # golden section
    return GOLDEN_MEAN * e, e


def minimize_bounded(func: Callable[[float], float], lower: float, upper: float, xatol: float = 1e-5,
                     maxiter: int = 500) -> BoundedMinimum:
    """The minimum of func on [lower, upper], as scipy.optimize.minimize_scalar(func, bounds=(lower, upper),
    method="bounded", options={"xatol": xatol}) finds it (Brent's parabolic / golden-section search).

    Like scipy, reaching maxiter function evaluations is reported in `status`, not raised."""
    if not (math.isfinite(lower) and math.isfinite(upper)):
        raise ValueError("Optimization bounds must be finite scalars.")
    if lower > upper:
        raise ValueError("The lower bound exceeds the upper bound.")
    a, b, xatol = float(lower), float(upper), float(xatol)
    fulc = a + GOLDEN_MEAN * (b - a)
    nfc = xf = fulc
    rat = e = 0.0
    fx = float(func(xf))
    num, status, fu = 1, 0, math.inf
    ffulc = fnfc = fx
    tol1 = SQRT_EPS * abs(xf) + xatol / 3.0
    while abs(xf - 0.5 * (a + b)) > (2.0 * tol1 - 0.5 * (b - a)):
        rat, e = _bounded_step(xf, fx, nfc, fnfc, fulc, ffulc, a, b, e, rat, tol1)
        x = xf + _sign_or_one(rat) * _nan_max(abs(rat), tol1)
        fu = float(func(x))
        num += 1
        if fu <= fx:
            a, b = (xf, b) if x >= xf else (a, xf)
            fulc, ffulc, nfc, fnfc, xf, fx = nfc, fnfc, xf, fx, x, fu
        else:
            a, b = (x, b) if x < xf else (a, x)
            if fu <= fnfc or nfc == xf:
                fulc, ffulc, nfc, fnfc = nfc, fnfc, x, fu
            elif fu <= ffulc or fulc == xf or fulc == nfc:
                fulc, ffulc = x, fu
        tol1 = SQRT_EPS * abs(xf) + xatol / 3.0
        if num >= maxiter:
            status = 1
            break
    if math.isnan(xf) or math.isnan(fx) or math.isnan(fu):
        status = 2
    return BoundedMinimum(xf, fx, num, status)


__all__ = ["BoundedMinimum", "RootResult", "brentq", "brentq_result", "minimize_bounded"]
