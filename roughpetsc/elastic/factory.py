"""The operator of a boundary, by name: the one place that maps ``-boundary`` to a compliance."""

from ..errors import ParameterError

BOUNDARIES = ("periodic", "free")


def make_operator(boundary, grid, E_star, comm, fft_threads=1, fft_effort="FFTW_MEASURE"):
    """The compliance of ``boundary`` on ``grid``: :class:`Westergaard` (periodic) or :class:`FreeBoundary` (free).

    Parameters are those of the operators; ``grid`` and ``E_star`` in the units the operator works in.
    """
    if boundary == "periodic":
        from .westergaard import Westergaard

        return Westergaard(grid, E_star, comm, fft_threads, fft_effort)
    if boundary == "free":
        from .love import FreeBoundary

        return FreeBoundary(grid, E_star, comm, fft_threads, fft_effort)
    raise ParameterError("boundary", f"the boundary is one of {', '.join(BOUNDARIES)}, got '{boundary}'")
