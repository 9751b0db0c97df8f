"""The periodic Westergaard operator (3.33) as a matrix-free PETSc shell Mat.

``w = F^-1[ F[p] / (pi E* |k|) ]`` for k != 0; the k = 0 mode carries no displacement (docs/conventions.md),
so the mean gap equals the rigid separation (3.38).
"""

import numpy as np
from petsc4py import PETSc

from ..errors import ParameterError
from ..fft.serial import SerialTransform
from ..surface.spectra import rfft_multiplicity
from .operator import FilterOperator, log_event, per_float, wavenumber_modulus


def periodic_transform(grid, comm, threads, effort):
    """The FFT pair of the periodic cell: a direct 2-D FFTW plan on one rank, the slab pair on several."""
    if comm.getSize() == 1:
        return SerialTransform(grid, threads, effort)
    from ..fft.slab import SlabTransform

    return SlabTransform(grid, comm.tompi4py(), effort)


def stiffness_symbol(grid, E_star, spectral_slice):
    """The inverse symbol pi E* |k| of the compliance (3.33) per float of a spectral block, 1/(n0 n1) folded in."""
    return per_float(np.pi * E_star * wavenumber_modulus(grid, *spectral_slice) / grid.size)


class Westergaard(FilterOperator):
    """Compliance of the periodic half-space, (3.33), applied through FFTW.

    Parameters
    ----------
    grid : surfaces.Grid
        The periodic cell.
    E_star : float
        Composite modulus E* (1.6) in pressure units.
    comm : petsc4py.PETSc.Comm
        Communicator; on one rank a direct 2-D FFTW plan is used.
    threads : int
        FFTW threads of the one-rank plan.
    effort : str
        FFTW planner flag.

    The preconditioner's ``stiffness`` is ``F^-1[pi E* max(|k|, 1/L) F[source]]``: the k = 0 mode is kept,
    as Polonsky-Keer needs the mean under displacement control.
    """

    boundary = "periodic"

    def __init__(self, grid, E_star, comm=None, threads=1, effort="FFTW_MEASURE"):
        if not (isinstance(E_star, (int, float, np.integer, np.floating)) and E_star > 0 and np.isfinite(E_star)):
            raise ParameterError("E_star", f"the composite modulus must be positive and finite, got {E_star!r}")
        comm = comm or PETSc.COMM_WORLD
        self.E_star = float(E_star)
        self.transform = periodic_transform(grid, comm, threads, effort)
        self._set_layout(grid, comm)
        k = wavenumber_modulus(grid, *self.transform.spectral_slice)
        with np.errstate(divide="ignore"):
            # The 1/(n0 n1) of the unnormalised FFT pair is folded into the symbols.
            self.compliance_symbol = per_float(np.where(k > 0, 1.0 / (np.pi * self.E_star * k), 0.0) / grid.size)
        longest = 1.0 / max(grid.l0, grid.l1)
        self._stiffness = stiffness_symbol(grid, self.E_star, self.transform.spectral_slice)
        self.preconditioner_symbol = per_float(np.pi * self.E_star * np.maximum(k, longest) / grid.size)

    @property
    def diagonal(self):
        """The (constant) diagonal of the compliance matrix: mean of its symbol over the full spectrum."""
        k = wavenumber_modulus(self.grid)
        with np.errstate(divide="ignore"):
            return self._spectral_mean(np.where(k > 0, 1.0 / (np.pi * self.E_star * k), 0.0))

    @property
    def stiffness_diagonal(self):
        """The (constant) diagonal of the stiffness matrix S of :meth:`elastic_pressure`."""
        return self._spectral_mean(np.pi * self.E_star * wavenumber_modulus(self.grid))

    def _spectral_mean(self, symbol):
        # rfft layout: a column that stands for two modes of the full spectrum counts twice.
        return float((symbol * rfft_multiplicity(self.grid.n1)).sum() / self.grid.size)

    @log_event("RPStiffness")
    def elastic_pressure(self, displacement, out):
        """``out = F^-1[pi E* |k| F[displacement]]``: the pressure less its mean that makes ``displacement``."""
        self.applications += 1
        self._filter(self.local(displacement, readonly=True), self.local(out), self._stiffness)

    def pressure_surface(self, heights, out):
        """``out = F^-1[pi E* |k| F[heights]]``: the complete-contact pressure p_c of (2.47)."""
        self._filter(self.local(heights, readonly=True), self.local(out), self._stiffness)


