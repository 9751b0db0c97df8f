"""The 2-D real FFT pair on one rank: pyFFTW plans made once, run in place on the Vec's memory."""

import numpy as np

from .plans import planner_effort


class SerialTransform:
    """2-D real FFT pair on one rank through pyFFTW plans made once."""

    def __init__(self, grid, threads, effort):
        import pyfftw

        effort = planner_effort(effort)
        shape = grid.shape
        self._alignment = pyfftw.simd_alignment
        self.real = pyfftw.empty_aligned(shape, dtype="float64")
        self.spectrum = pyfftw.empty_aligned((shape[0], shape[1] // 2 + 1), dtype="complex128")
        # Aligned plans run twice as fast as FFTW_UNALIGNED ones here; unaligned memory is copied via self.real.
        self._forward = pyfftw.FFTW(self.real, self.spectrum, axes=(0, 1), direction="FFTW_FORWARD",
                                    flags=(effort,), threads=threads)
        self._backward = pyfftw.FFTW(self.spectrum, self.real, axes=(0, 1), direction="FFTW_BACKWARD",
                                     flags=(effort, "FFTW_DESTROY_INPUT"), threads=threads)
        self.local_rows = slice(0, shape[0])
        self.spectral_slice = (slice(None), slice(None))

    def _aligned(self, array):
        return array.ctypes.data % self._alignment == 0

    def filter(self, source, target, symbol):
        """``target = irfft2(symbol * rfft2(source))``, unnormalised; ``symbol`` real, per float of the spectrum."""
        if self._aligned(source):
            self._forward.update_arrays(source, self.spectrum)
        else:
            self.real[...] = source
            self._forward.update_arrays(self.real, self.spectrum)
        self._forward.execute()
        self.spectrum.view(np.float64).__imul__(symbol)
        direct = self._aligned(target)
        self._backward.update_arrays(self.spectrum, target if direct else self.real)
        self._backward.execute()
        if not direct:
            target[...] = self.real
