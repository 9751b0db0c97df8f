"""The work counter of an ensemble: which surface a group solves next (dynamic scheduling over ranks).

The counter and its two transports: docs/runtime.md, "Ensembles over ranks".
"""

import numpy as np

TAG_RECORD, TAG_NEXT, TAG_ITEM = 11, 12, 13   # message tags: a finished surface, a request, its answer
IDLE_SLEEP = 0.01          # seconds between looks for messages when a rank has nothing else to do


class WorkCounter:
    """The next work item for the group leaders: an atomic counter on world rank 0.

    One-sided (``Fetch_and_op`` on a window) where MPI supports it; otherwise by messages rank 0 answers
    between its load steps (:meth:`roughpetsc.ensemble.runner.Ensemble.poll`).
    """

    def __init__(self, comm, items, use_window=True):
        from mpi4py import MPI

        self.comm, self.items = comm, items
        self.window = None
        self.next_local = 0                      # rank 0's counter in message mode
        self.leaders_done = 0                    # message mode: leaders told "no more work"
        if use_window:
            try:
                self.window = MPI.Win.Allocate(8 if comm.Get_rank() == 0 else 0, 8, comm=comm)
            except MPI.Exception:
                self.window = None
        if not comm.allreduce(self.window is not None, op=MPI.LAND) and self.window is not None:
            self.window.Free()
            self.window = None
        if self.window is not None and comm.Get_rank() == 0:
            self.window.Lock(0, MPI.LOCK_EXCLUSIVE)
            self.window.Put([np.zeros(1, np.int64), MPI.INT64_T], 0)
            self.window.Unlock(0)
        comm.Barrier()
        self.mode = "one-sided" if self.window is not None else "messages"

    def next(self):
        """Called by a group leader: the next item (an index into ``items``) or -1 when none is left."""
        from mpi4py import MPI

        if self.window is not None:
            one, value = np.ones(1, np.int64), np.zeros(1, np.int64)
            self.window.Lock(0, MPI.LOCK_SHARED)
            self.window.Fetch_and_op([one, MPI.INT64_T], [value, MPI.INT64_T], 0, 0, MPI.SUM)
            self.window.Unlock(0)
            k = int(value[0])
        elif self.comm.Get_rank() == 0:
            k, self.next_local = self.next_local, self.next_local + 1
        else:
            self.comm.send(None, dest=0, tag=TAG_NEXT)
            k = self.comm.recv(source=0, tag=TAG_ITEM)
        return k if k < len(self.items) else -1

    def exhaust(self):
        """Rank 0: no more items for anybody; returns how many had been handed out."""
        from mpi4py import MPI

        handed = self.next_local
        if self.window is not None:
            end, old = np.array([len(self.items)], np.int64), np.zeros(1, np.int64)
            self.window.Lock(0, MPI.LOCK_EXCLUSIVE)
            self.window.Fetch_and_op([end, MPI.INT64_T], [old, MPI.INT64_T], 0, 0, MPI.REPLACE)
            self.window.Unlock(0)
            handed = int(old[0])
        self.next_local = max(self.next_local, len(self.items))
        return min(handed, len(self.items))

    def answer(self, source):
        """Rank 0, message mode: give ``source`` its next item."""
        k, self.next_local = self.next_local, self.next_local + 1
        if k >= len(self.items):
            self.leaders_done += 1
        self.comm.send(k, dest=source, tag=TAG_ITEM)

    def free(self):
        if self.window is not None:
            self.window.Free()
