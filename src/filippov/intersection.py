"""Sliding on the intersection of two switching surfaces: the choice of the sliding field.

Where two surfaces h_j = 0 and h_k = 0 meet, four regions do: their fields F_ab (a the
side of h_j, b of h_k, each - or +). Filippov's convex hull of the four leaves a whole
segment of fields tangent to the intersection; a sliding field has to be chosen.

Taken here: the bilinear interpolation of Dieci and Lopez (L. Dieci, L. Lopez, "Sliding
motion on discontinuity surfaces of high co-dimension. A construction for selecting a
Filippov vector field", Numer. Math. 117 (2011) 779-811),

    F = (1-alpha)(1-beta) F_-- + (1-alpha) beta F_-+ + alpha (1-beta) F_+- + alpha beta F_++,

with (alpha, beta) in [0, 1]^2 such that F is tangent to both surfaces: alpha the weight
of h_j's + side, beta of h_k's. Where the intersection attracts (nodally), there is
exactly one such pair (whether it attracts is asked of the slide that reaches it:
rules.slides_into_intersection); it is smooth in the state, reduces to Filippov's field on one
surface where alpha or beta reaches 0 or 1 (the ends of the slide on the intersection),
and to the sliding field of each surface alone where the system is decoupled.

Compared with it, the two *nested* choices (slide on one surface first, then on the
intersection within it as on a surface of the slide: :func:`nested_field`). Where the
three agree the system settles the field; where they do not, the choice is the model's
(``SurfacesSystem.intersection = "bilinear"`` takes this one), and a run is refused
rather than given one silently (:mod:`filippov.several`).
"""
from __future__ import annotations

import numpy as np


def _speeds(system, sigma, j, k, z):
    """(w_j, w_k, F): the four fields' speeds along grad h_j and grad h_k, [a][b] with
    index 0 for the - side and 1 for the + side, and the fields, at one state z."""
    G = system.grads(z)
    F = np.empty((2, 2, z.size))
    for a in (0, 1):
        for b in (0, 1):
            rho = list(sigma)
            rho[j], rho[k] = 2 * a - 1, 2 * b - 1
            F[a, b] = system.region_field(tuple(rho), z)
    return F @ G[j], F @ G[k], F


#: how far past the square [0, 1]^2 the weights are continued (``extend``): the ends of a
#: slide are their roots at 0 or 1, which a step past an end brackets; farther on the
#: continued weights run to a pole (where the two speeds along a surface are equal) and
#: the field, a sum of huge terms, is rounding: a stage there gave w' = 1.0625 for 1,
#: accepted, and the end came 3.9e-4 late (a review). Past it: no field (NaN), a step
#: whose stage meets it is rejected and shortened.
EXTEND_MAX = 1.0


def bilinear_weights(wj: np.ndarray, wk: np.ndarray, extend: bool = False):
    """(alpha, beta) that make the bilinear field tangent to both surfaces (``wj[a, b]``,
    ``wk[a, b]``: the fields' speeds along each gradient): the one pair in [0, 1]^2, or
    None where there is none or more than one; ``extend``: the real pair nearest the
    square, also outside it by up to EXTEND_MAX (the weights continued past the ends of
    a slide, where they cross 0 or 1 smoothly: the ends are the roots of the weights,
    found as sections)."""
    def alpha_of(beta):
        a0 = (1 - beta) * wj[0, 0] + beta * wj[0, 1]
        a1 = (1 - beta) * wj[1, 0] + beta * wj[1, 1]
        return a0, a0 - a1

    def q(beta):   # the second condition times (a0 - a1): a quadratic in beta
        a0, den = alpha_of(beta)
        return ((1 - beta) * (wk[0, 0] * den + a0 * (wk[1, 0] - wk[0, 0]))
                + beta * (wk[0, 1] * den + a0 * (wk[1, 1] - wk[0, 1])))

    q0, qh, q1 = q(0.0), q(0.5), q(1.0)
    c2 = 2.0 * (q1 - 2.0 * qh + q0)
    c1 = q1 - q0 - c2
    roots = np.roots([c2, c1, q0]) if c2 != 0.0 or c1 != 0.0 else np.array([])
    found = []
    for beta in roots:
        if abs(beta.imag) > 1e-12 * max(1.0, abs(beta.real)):
            continue
        a0, den = alpha_of(beta.real)
        if den != 0.0:
            found.append((float(a0 / den), float(beta.real)))
    inside = [w for w in found if 0.0 <= w[0] <= 1.0 and 0.0 <= w[1] <= 1.0]
    if not extend:
        return inside[0] if len(inside) == 1 else None
    if not found:
        return None
    outside = lambda w: max(-w[0], w[0] - 1.0, -w[1], w[1] - 1.0, 0.0)  # noqa: E731
    nearest = min(found, key=outside)
    return nearest if outside(nearest) <= EXTEND_MAX else None


def bilinear_field(system, sigma, j, k, z, extend=True):
    """The bilinear sliding field on the intersection of h_j and h_k beside region
    ``sigma`` (its other digits), at z (n,) or a batch (n, b), its weights continued
    past the square (``extend``: a slide's stay steps a little past its end); NaN where
    it has none."""
    z = np.asarray(z, dtype=float)
    if z.ndim == 2:
        return np.stack([bilinear_field(system, sigma, j, k, z[:, i], extend)
                         for i in range(z.shape[1])], axis=1)
    wj, wk, F = _speeds(system, sigma, j, k, z)
    w = bilinear_weights(wj, wk, extend)
    if w is None:
        return np.full(z.size, np.nan)
    a, b = w
    return ((1 - a) * (1 - b) * F[0, 0] + (1 - a) * b * F[0, 1] + a * (1 - b) * F[1, 0]
            + a * b * F[1, 1])


def weights(system, sigma, j, k, z):
    """(alpha, beta) at one state, continued past the square (NaN, NaN where there are
    none)."""
    wj, wk, _ = _speeds(system, sigma, j, k, np.asarray(z, dtype=float))
    w = bilinear_weights(wj, wk, extend=True)
    return (np.nan, np.nan) if w is None else w


def _filippov(f_minus, f_plus, grad):
    """Filippov's field on the surface with gradient grad between f_minus and f_plus."""
    a, b = grad @ f_minus, grad @ f_plus
    return (a * f_plus - b * f_minus) / (a - b)


def nested_field(system, sigma, first, second, z):
    """Slide on surface ``first`` on either side of ``second``, then on the intersection
    as Filippov's field between those two slides across ``second``: one of the nested
    choices, at one state z."""
    z = np.asarray(z, dtype=float)
    G = system.grads(z)
    slides = []
    for c in (-1, 1):
        rho = list(sigma)
        rho[second] = c
        sides = []
        for d in (-1, 1):
            rho[first] = d
            sides.append(np.asarray(system.region_field(tuple(rho), z), dtype=float))
        slides.append(_filippov(sides[0], sides[1], G[first]))
    return _filippov(slides[0], slides[1], G[second])
