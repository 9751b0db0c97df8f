"""The progress line of a long solve on a terminal."""

import time

import numpy as np


class Progress:
    """Prints where a running load step is, at most every ``interval`` seconds of wall time.

    A line names the load step, the inner solve of the step (a root find or an augmented Lagrangian solves
    several in a row), the iteration, the natural residual and the seconds since the step began::

          ... step 3 of 95 (pstar 0.02): inner solve 2, iteration 120, KKT natural 1.20e-05, 4.1 s

    Nothing is printed for a step shorter than ``interval``.
    """

    def __init__(self, interval, stream):
        self.interval = interval
        self.stream = stream
        self.printed_at = -np.inf
        self.step = "the solve"
        self.step_started = time.perf_counter()
        self.inner = 0
        self.last_iteration = -1

    def start_step(self, index, count, kind, value):
        """A new load step: the ``index``-th (from 0) of ``count``, ``kind`` (pstar, pbar, gbar) = ``value``."""
        self.step = f"step {index + 1} of {count} ({kind} {value:g})"
        self.step_started = time.perf_counter()
        self.inner = 0
        self.last_iteration = -1

    def __call__(self, iteration, natural, seconds):
        # Every inner solve records its first iteration again: 0, or where the previous one stopped.
        if iteration <= self.last_iteration or iteration == 0:
            self.inner += 1
        self.last_iteration = iteration
        now = time.perf_counter()
        elapsed = now - self.step_started
        if elapsed >= self.interval and now - self.printed_at >= self.interval:
            self.printed_at = now
            print(f"  ... {self.step}: inner solve {max(self.inner, 1)}, iteration {iteration}, KKT natural "
                  f"{natural:.2e}, {elapsed:.1f} s", file=self.stream, flush=True)
