"""s0(theta) of Eq. (B.15) (Fig. B.2) as a model: the closed form and the root
finding of :mod:`filippov.analytic.s0`, no system to integrate."""
from ..analytic.s0 import residual, s0_lambert, s0_root  # noqa: F401  (the model's pieces)

NAME = "s0_closed_form"
