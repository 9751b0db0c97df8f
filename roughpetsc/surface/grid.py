"""The periodic cell of a surface: nodes, lengths and wavenumbers (the Fourier pair (2.1)/(2.2))."""

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError


@dataclass(frozen=True)
class Grid:
    """A periodic cell of ``n0 x n1`` nodes (positive whole numbers) and size ``l0 x l1`` (positive, finite)."""

    n0: int
    n1: int
    l0: float = 1.0
    l1: float = 1.0

    def __post_init__(self):
        for name in ("n0", "n1"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
                raise ParameterError(name, f"the number of nodes {name} must be a positive whole number, got {value!r}")
        for name in ("l0", "l1"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float, np.integer, np.floating)) and value > 0 and np.isfinite(value)):
                raise ParameterError(name, f"the cell side {name} must be positive and finite, got {value!r}")

    @property
    def shape(self):
        return (self.n0, self.n1)

    @property
    def size(self):
        return self.n0 * self.n1

    @property
    def area(self):
        return self.l0 * self.l1

    def coordinates(self):
        """Node coordinates ``(y, x)`` as broadcastable column and row arrays."""
        y = np.arange(self.n0)[:, None] * (self.l0 / self.n0)
        x = np.arange(self.n1)[None, :] * (self.l1 / self.n1)
        return y, x

    def rfft_wavenumbers(self, rows=slice(None)):
        """Wavenumbers (k0, k1) [cycles/length] of the ``rfft2`` layout, shapes ``(rows, 1)``, ``(1, n1 // 2 + 1)``."""
        k0 = np.fft.fftfreq(self.n0, d=self.l0 / self.n0)[rows][:, None]
        k1 = np.fft.rfftfreq(self.n1, d=self.l1 / self.n1)[None, :]
        return k0, k1


def square_grid(n1, n0=0, length=1.0):
    """The :class:`Grid` of ``n0 x n1`` square nodes (``n0 = 0``: ``n1``) and cell length ``length`` along x."""
    n0 = n0 or n1
    if n1 < 2 or n0 < 1:
        raise ParameterError("n1", f"the grid needs at least 2 columns and 1 row, got {n0} x {n1} nodes")
    if not (length > 0 and np.isfinite(length)):
        raise ParameterError("length", f"the cell length must be positive and finite, got {length}")
    return Grid(n0, n1, length * n0 / n1, length)
