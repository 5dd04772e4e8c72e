"""Radau IIA collocation with any odd number of stages, as a scipy ``OdeSolver``.

scipy's ``Radau`` is the 3-stage method (order 5). At the tolerances this project
integrates stiff fields with (rtol 1e-12) its steps are set by an error estimate of
order 3, so a stiff sliding stay costs ~1000 steps whatever eps is. The s-stage
Radau IIA method has order 2s - 1 and an embedded error estimate of order s
(Hairer & Wanner, *Solving ODEs II*, 2nd ed., sec. IV.8): with s = 5 the step
grows like tol^(1/6) instead of tol^(1/4), ten times fewer steps at 1e-12.

What is the same as scipy's Radau: simplified Newton iterations on the stage
increments Z (collocation: Z = h (A x I) f(y + Z)), the stiffly filtered error
estimate (I - h gamma0 J)^-1 (gamma0 h f(y0) + sum_j e_j Z_j), the collocation
polynomial as dense output (error of the order of the estimate). What is simpler:
the Newton matrix I - h (A x J) is factorised whole (s n x s n real LU; the
fields here have n <= a few), and the Jacobian (finite differences, one
vectorized field call) and the factorisation are renewed every step: a step
costs one LU more and no heuristics about when to reuse them.

The tableaux (3, 5, 7 stages) are constants computed from their definitions (see
``Tableau``); the tests recompute them and check the 3-stage one against scipy's.
"""
from __future__ import annotations

import functools

import numpy as np
from scipy.integrate import OdeSolver
from scipy.integrate import DenseOutput  # the public base class of dense outputs
from scipy.linalg import lu_factor, lu_solve

NEWTON_MAXITER = 7     # simplified Newton iterations before the step is shrunk
MIN_FACTOR, MAX_FACTOR, SAFETY = 0.2, 8.0, 0.9


#: stages -> (c, A, gamma0, e, to_poly), each rounded to double from a 60-digit
#: evaluation of the definitions (mpmath; the script is the test
#: test_vendored_tableaux_are_their_definitions, which recomputes them in double
#: and compares). Constants, not a LAPACK computation at import: the same bits on
#: every CPU.
_TABLEAUX = {
    3: (
        (0.1550510257216822, 0.6449489742783178, 1.0,),
        ((0.1968154772236604, -0.06553542585019839, 0.02377097434822015,),
         (0.3944243147390873, 0.2920734116652285, -0.04154875212599793,),
         (0.37640306270046725, 0.5124858261884216, 0.1111111111111111,)),
        0.27488882959567734,
        (-2.7623054547485992, 0.3799355982527289, -0.0916296098652258,),
        ((10.048809399827416, -1.382142733160749, 0.3333333333333333,),
         (-25.62959144707664, 10.296258113743306, -2.6666666666666665,),
         (15.580782047249224, -8.914115380582556, 3.3333333333333335,))),
    5: (
        (0.05710419611451768, 0.2768430136381238, 0.5835904323689168, 0.8602401356562195, 1.0,),
        ((0.07299886431790333, -0.02673533110794557, 0.018676929763984353, -0.01287910609330644, 0.005042839233882015,),
         (0.15377523147918246, 0.14621486784749352, -0.03644456890512809, 0.02123306311930472, -0.007935579902728777,),
         (0.14006304568480987, 0.29896712949128346, 0.16758507013524895, -0.03396910168661774, 0.010944288744192253,),
         (0.14489430810953477, 0.2765000687601592, 0.32579792291042103, 0.12875675325490976, -0.015708917378805327,),
         (0.14371356079122594, 0.28135601514946207, 0.31182652297574126, 0.22310390108357075, 0.04,)),
        0.15906584442746913,
        (-4.418997716796381, 0.57923485225667, -0.199237560953468, 0.09416748369194548, -0.03181316888549383,),
        ((27.78093394406464, -3.641478498049213, 1.2525477211691187, -0.5920031671845428, 0.2,),
         (-208.02785730090133, 77.88337605511782, -29.167414317829696, 14.111895563613205, -4.8,),
         (524.1878839694918, -264.89491356822634, 137.90290440413477, -72.39587480540027, 25.2,),
         (-543.8283560361325, 317.67586907995275, -202.09087094360743, 123.04335789978718, -44.8,),
         (199.88739542347736, -127.022853068795, 92.10283313613321, -64.16737549081559, 25.2,))),
    7: (
        (0.029316427159784893, 0.1480785996684843, 0.3369846902811543, 0.5586715187715501, 0.7692338620300545, 0.9269456713197411, 1.0,),
        ((0.03754626499392133, -0.0140393345564604, 0.0103527896007423, -0.008158322540275011, 0.006388413879534685, -0.004602326779148656, 0.0018289425614706437,),
         (0.08014759651561897, 0.08106206398589154, -0.021237992120711036, 0.014000291238817119, -0.010234185730090163, 0.0071534651513645905, -0.0028126393724067235,),
         (0.0720638469418819, 0.17106835498388662, 0.10961456404007211, -0.024619871728984055, 0.014760377043950817, -0.009575259396791401, 0.0036726783971383057,),
         (0.07570512581982441, 0.15409015514217114, 0.2271077366732024, 0.11747818703702478, -0.023810827153044174, 0.012709985533661206, -0.004608844281289633,),
         (0.07391234216319184, 0.16135560761594242, 0.2068672415521042, 0.23700711534269422, 0.10308679353381345, -0.018854139152580447, 0.0058589009748887914,),
         (0.07470556205979623, 0.1583072238724687, 0.21415342326720002, 0.21987784703186003, 0.19875212168063527, 0.06926550160550914, -0.00811600819772829,),
         (0.07449423555601031, 0.15910211573365074, 0.21235188950297781, 0.22355491450728324, 0.19047493682211558, 0.1196137446126562, 0.02040816326530612,)),
        0.11189646530003508,
        (-6.084307291132809, 0.7832779430920006, -0.2635901496382284, 0.12669914419515418, -0.0723848528985174, 0.04336361600925824, -0.01598520932857644,),
        ((54.374436894128614, -7.000024004259187, 2.355661091987557, -1.1322890661061344, 0.6468913267673587, -0.38753338537535237, 0.14285714285714285,),
         (-809.604447567907, 295.72882206751626, -108.43698367594611, 53.45541143713203, -30.856719667980922, 18.571060264328636, -6.857142857142857,),
         (4356.1008389578465, -2118.907019153766, 1063.3426386156493, -570.1028912055015, 340.2585258530358, -207.83495021012072, 77.14285714285714,),
         (-11271.767934426613, 6270.7306415830535, -3770.1808571400634, 2308.4681482334067, -1459.5261955536778, 915.1333401610366, -342.85714285714283,),
         (15165.697701626303, -9102.864560299675, 6126.120473885261, -4190.257632877243, 2857.2748261860943, -1861.1136656635979, 707.1428571428571,),
         (-10230.214794534506, 6441.038378576283, -4675.3990102870885, 3485.0725047391993, -2561.697312686989, 1752.0573770502433, -678.8571428571429,),
         (2735.414199050748, -1778.7262387691535, 1362.1980775102002, -1085.503251260887, 853.8999845427503, -616.4256282165146, 245.14285714285714,))),
}


class Tableau:
    """Nodes c, matrix A, the real eigenvalue gamma0 of A and the error weights e of
    the s-stage Radau IIA method; ``to_poly`` maps stage values to the coefficients
    of the collocation polynomial (powers 1..s of the step fraction).

    Definitions: c are the zeros of P_s(2x - 1) - P_{s-1}(2x - 1) (c_s = 1);
    A_ij = integral from 0 to c_i of the j-th Lagrange polynomial on c; the
    embedded estimate puts weight gamma0 on f(y0) and weights b_hat on the stages
    that integrate polynomials of degree < s exactly, and e = A^-T (b_hat - b)
    turns it into gamma0 h f0 + sum_j e_j Z_j (b = A's last row)."""

    def __init__(self, stages: int):
        if stages not in _TABLEAUX:
            raise ValueError(f"stages must be one of {sorted(_TABLEAUX)} (odd: one real "
                             f"eigenvalue of A for the error estimate), got {stages!r}")
        c, A, gamma0, e, to_poly = _TABLEAUX[stages]
        self.c, self.A, self.gamma0 = np.array(c), np.array(A), gamma0
        self.e, self.to_poly = np.array(e), np.array(to_poly)
        self.stages, self.estimate_order = stages, stages


@functools.lru_cache(maxsize=None)
def tableau(stages: int) -> Tableau:
    return Tableau(stages)


class RadauIIA(OdeSolver):
    """Implicit Radau IIA collocation, order 2 stages - 1 (default 5 stages: order 9).

    Parameters as scipy's ``Radau`` (``fun``, ``t0``, ``y0``, ``t_bound``,
    ``max_step``, ``rtol``, ``atol``, ``vectorized``, ``first_step``), plus
    ``stages`` (odd). ``atol`` may be changed between steps (it is read every step).
    """

    def __init__(self, fun, t0, y0, t_bound, max_step=np.inf, rtol=1e-3, atol=1e-6,
                 vectorized=False, first_step=None, stages=5, **extraneous):
        super().__init__(fun, t0, y0, t_bound, vectorized)
        if not (max_step > 0):
            raise ValueError(f"max_step must be > 0, got {max_step!r}")
        self.max_step, self.rtol, self.atol = max_step, rtol, atol
        self.tab = tableau(stages)
        self.f = self.fun(self.t, self.y)
        self.h_abs = (self._first_step() if first_step is None else abs(first_step))
        self.h_abs = min(self.h_abs, max_step)
        self.poly = None          # collocation polynomial of the last step (s x n)
        self.h_old = None
        self.rejected = False
        self.eta = 1.0            # Newton's contraction estimate, carried over

    # ------------------------------------------------------------------ helpers
    def _scale(self, y):
        return np.asarray(self.atol) + self.rtol * np.abs(y)

    def _first_step(self):
        # h0 with h0 |f0| ~ 1e-2 of the state scale (Hairer's starting guess)
        d0 = np.linalg.norm(self.y / self._scale(self.y)) / np.sqrt(self.n)
        d1 = np.linalg.norm(self.f / self._scale(self.y)) / np.sqrt(self.n)
        h = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
        return min(h, abs(self.t_bound - self.t))

    def _jacobian(self, t, y, f):
        # forward differences, all columns in one vectorized call (central differences,
        # variational.fd_jacobian, would cost 2 n calls per step)
        delta = np.sqrt(np.finfo(float).eps) * np.maximum(np.abs(y), self._scale(y) / self.rtol)
        delta = np.maximum(delta, 1e-300)
        cols = y[:, None] + np.diag(delta)
        return (self.fun_vectorized(t, cols) - f[:, None]) / delta[None, :]

    def _rms(self, v, scale):
        return float(np.sqrt(np.mean((v / scale) ** 2)))

    # ------------------------------------------------------------------ one step
    def _newton(self, t, y, h, J, Z, scale):
        """Simplified Newton on Z = h (A x I) f(y + Z); (converged, iterations, Z).

        Converged when the distance to the solution, estimated as eta |dZ| with
        eta = rate / (1 - rate), is below tol. In the first iteration the rate is
        not known yet: eta comes from the last step (as in Hairer's RADAU5), so
        that a prediction already at the rounding noise of a stiff field is
        accepted instead of being iterated on noise (whose rate is ~1)."""
        tab, n, s = self.tab, self.n, self.tab.stages
        lu = lu_factor(np.eye(s * n) - h * np.kron(tab.A, J))
        tol = max(10 * np.finfo(float).eps / self.rtol, min(0.03, self.rtol ** 0.5))
        eta = max(self.eta, np.finfo(float).eps) ** 0.8
        norm_old = None
        for k in range(NEWTON_MAXITER):
            F = self.fun_vectorized(t + tab.c * h, y[:, None] + Z.T).T      # (s, n)
            if not np.all(np.isfinite(F)):
                return False, k + 1, None
            dZ = lu_solve(lu, (h * tab.A @ F - Z).ravel()).reshape(s, n)
            norm = self._rms(dZ, scale)
            if norm_old is not None:
                rate = norm / norm_old
                # diverging, or not converging within the iterations left
                if rate >= 1.0 or rate ** (NEWTON_MAXITER - k) / (1 - rate) * norm > tol:
                    return False, k + 1, None
                eta = rate / (1 - rate)
            Z = Z + dZ
            if norm == 0.0 or eta * norm < tol:
                self.eta = eta
                return True, k + 1, Z
            norm_old = norm
        return False, NEWTON_MAXITER, None

    def _predict(self, h):
        """Stage increments guessed from the last collocation polynomial."""
        if self.poly is None:
            return np.zeros((self.tab.stages, self.n))
        x = 1.0 + self.tab.c * h / self.h_old
        powers = x[:, None] ** np.arange(1, self.tab.stages + 1)
        return powers @ self.poly - self.poly.sum(axis=0)

    def _step_impl(self):
        t, y, f, tab = self.t, self.y, self.f, self.tab
        direction = self.direction
        min_step = 10 * np.abs(np.nextafter(t, direction * np.inf) - t)
        h_abs = min(max(self.h_abs, min_step), self.max_step)
        J = self._jacobian(t, y, f)
        while True:
            if h_abs < min_step:
                return False, self.TOO_SMALL_STEP
            h = h_abs * direction
            t_new = t + h
            if direction * (t_new - self.t_bound) > 0:
                t_new = self.t_bound
            h = t_new - t
            h_abs = abs(h)
            scale = self._scale(y)
            ok, iters, Z = self._newton(t, y, h, J, self._predict(h), scale)
            if not ok:
                h_abs *= 0.5
                self.rejected = True
                continue
            y_new = y + Z[-1]
            scale = np.asarray(self.atol) + self.rtol * np.maximum(np.abs(y), np.abs(y_new))
            lu_err = lu_factor(np.eye(self.n) - h * tab.gamma0 * J)
            raw = tab.gamma0 * h * f + tab.e @ Z
            err = lu_solve(lu_err, raw)
            err_norm = self._rms(err, scale)
            if err_norm > 1.0 and self.rejected:
                # a stiff component can inflate the first estimate: filter it once more
                err = lu_solve(lu_err, tab.gamma0 * h * self.fun(t, y + err) + tab.e @ Z)
                err_norm = self._rms(err, scale)
            safety = SAFETY * (2 * NEWTON_MAXITER + 1) / (2 * NEWTON_MAXITER + iters)
            if not np.isfinite(err_norm) or err_norm > 1.0:
                factor = (MIN_FACTOR if not np.isfinite(err_norm) else
                          max(MIN_FACTOR, safety * err_norm ** (-1.0 / (tab.estimate_order + 1))))
                h_abs *= factor
                self.rejected = True
                continue
            break
        factor = MAX_FACTOR if err_norm == 0 else min(
            MAX_FACTOR, safety * err_norm ** (-1.0 / (tab.estimate_order + 1)))
        if self.rejected:
            factor = min(1.0, factor)
        self.rejected = False
        self.poly = tab.to_poly @ Z
        self.h_old = h
        self.y_prev = y
        self.t, self.y = t_new, y_new
        self.f = self.fun(t_new, y_new)
        self.h_abs = h_abs * factor
        return True, None

    def _dense_output_impl(self):
        # t_old: set by OdeSolver.step() after each step
        return CollocationOutput(self.t_old, self.t, self.y_prev, self.h_old, self.poly)


class CollocationOutput(DenseOutput):
    """y(t_old + x h) = y_old + sum_k P_k x^k, the step's collocation polynomial."""

    def __init__(self, t_old, t, y_old, h, poly):
        super().__init__(t_old, t)
        self.y_old, self.h, self.poly = y_old, h, poly

    def _call_impl(self, t):
        x = (np.asarray(t, dtype=float) - self.t_old) / self.h
        if x.ndim == 0:
            powers = x ** np.arange(1, self.poly.shape[0] + 1)
            return self.y_old + powers @ self.poly
        powers = x[None, :] ** np.arange(1, self.poly.shape[0] + 1)[:, None]   # (s, m)
        return self.y_old[:, None] + self.poly.T @ powers
