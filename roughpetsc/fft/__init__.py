"""The FFT layer: FFTW plans and wisdom, the serial 2-D pair, the slab pair over ranks, the zero-padded pair.

Nothing here knows about contact: a transform takes a real field and a real symbol and returns the filtered
field (:meth:`filter`). The elastic operators (:mod:`roughpetsc.elastic`) are built on it.
"""

from ..lazy import exports

__getattr__, __dir__, __all__ = exports(__name__, {
    "planner_effort": ("plans", "planner_effort"),
    "wisdom_path": ("plans", "wisdom_path"),
    "remembered_plans": ("plans", "remembered_plans"),
    "SerialTransform": ("serial", "SerialTransform"),
    "SlabTransform": ("slab", "SlabTransform"),
    "PaddedTransform": ("padded", "PaddedTransform"),
})
