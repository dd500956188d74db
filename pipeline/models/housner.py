"""pipeline.models.housner - Housner's rigid-base rocking block (paper eqs. 1-6).

Input : block (R, alpha), ground acceleration. Output: registered model ``housner``.

theta'' = -p^2 [sin(sigma alpha - theta) + (ag/g) cos(sigma alpha - theta)], p^2 = 3g/(4R), sigma
the active pivot. At rest until |ag| > g tan(alpha); at each impact (theta = 0) theta' <- r theta'
with r = 1 - 1.5 sin^2(alpha) by default (angular momentum about the new corner), pivot switches.
"""

from pipeline.models import kernels
from pipeline.models.base import RockingModel

MODEL = RockingModel(
    name="housner", kernel_code=kernels.HOUSNER, kappa=0.75, needs_foundation=False,
    default_restitution=lambda block: block.housner_restitution(),
    description="rigid base (Housner 1963); impacts dissipate with r = 1 - 1.5 sin^2(alpha)")
