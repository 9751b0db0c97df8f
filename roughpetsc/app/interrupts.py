"""Ctrl-C and a batch system's SIGTERM as a request to stop at the next safe point, on every rank alike.

Raising ``KeyboardInterrupt`` wherever the signal lands cannot end a run on several ranks cleanly: a
rank that leaves its solve strands the others in their next collective call, and a rank blocked in
one cannot even run Python's handler. So the first signal only sets a flag
(:class:`StopRequests`); the solvers look at it in the collective check that also enforces
``-solve_max_time`` (:meth:`roughpetsc.kkt.History.out_of_time`), every rank learns of a request
made on any rank (:func:`agreed`), and all of them leave the solve by the same iteration. A second
signal raises ``KeyboardInterrupt`` at once, for a person who does not want to wait.
"""

import signal

from ..parallel import allmax

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class StopRequests:
    """Context manager: inside it SIGINT and SIGTERM set :meth:`is_set` instead of raising.

    The handlers in place before are restored on exit. A second signal inside the block raises
    ``KeyboardInterrupt``.
    """

    def __init__(self):
        self.requested = False
        self.previous = {}

    def _handle(self, number, frame):
        if self.requested:
            raise KeyboardInterrupt
        self.requested = True

    def is_set(self):
        """True once a signal asked this process to stop."""
        return self.requested

    def __enter__(self):
        for number in STOP_SIGNALS:
            self.previous[number] = signal.signal(number, self._handle)
        return self

    def __exit__(self, *exception):
        for number, handler in self.previous.items():
            signal.signal(number, handler)
        return False


def agreed(comm, flag):
    """``flag`` of any rank of ``comm`` (mpi4py), on every rank: collective."""
    return bool(flag) if comm is None else bool(allmax(comm, [bool(flag)])[0])
