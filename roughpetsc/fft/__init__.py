"""The FFT layer: FFTW plans and wisdom, the serial 2-D pair, the slab pair over ranks, the zero-padded pair.

Nothing here knows about contact: a transform takes a real field and a real symbol and returns the filtered
field (:meth:`filter`). The elastic operators (:mod:`roughpetsc.elastic`) are built on it.
"""

from ..lazy import exports

__getattr__, __dir__, __all__ = exports(__name__, {
    "plans": "planner_effort wisdom_path remembered_plans",
    "serial": "SerialTransform",
    "slab": "SlabTransform",
    "padded": "PaddedTransform",
})
