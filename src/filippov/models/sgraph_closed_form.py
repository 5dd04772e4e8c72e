"""The graph of s(theta, omega, xi1, 0) xi1 (Eq. (23), Fig. 6) as a model: the
closed forms of :mod:`filippov.analytic.sgraph`, no system to integrate."""
from ..analytic.sgraph import image, image_limit, slope, slope_at_zero, xi1  # noqa: F401

NAME = "sgraph_closed_form"
