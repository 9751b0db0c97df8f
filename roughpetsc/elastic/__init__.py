"""The elastic layer: compliances of the half-space as matrix-free PETSc operators, and subsurface stresses.

:func:`make_operator` is the factory of the operator a problem is given (``-boundary``): the periodic
Westergaard compliance (3.33) or the free boundary's Love coefficients (3.31).
"""

from ..lazy import exports

__getattr__, __dir__, __all__ = exports(__name__, {
    "factory": "BOUNDARIES make_operator",
    "operator": "FilterOperator",
    "westergaard": "Westergaard",
    "love": "FreeBoundary",
    "split": "SplitCompliance",
    "stresses": "periodic_stresses free_stresses",
})
