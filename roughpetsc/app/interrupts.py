"""Ctrl-C and a batch system's SIGTERM as a request to stop at the next safe point, on every rank alike.

The first signal sets a flag that every rank checks at the same safe point (:func:`agreed`); a second raises
``KeyboardInterrupt``; a thread prints the closing line at once. Why: docs/runtime.md.
"""

import os
import signal
import threading

from ..parallel import allmax

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class StopRequests:
    """Context manager: inside it SIGINT and SIGTERM set :meth:`is_set` instead of raising; a second raises.

    ``announcement``, once set, is called once at the first request, from a thread that does not wait for the
    main one.
    """

    def __init__(self):
        self.requested = False
        self.signals = 0
        self.announcement = None
        self.announced = False
        self.lock = threading.Lock()  # a request comes wholly before or wholly after a replacement of files
        self.previous = {}
        self.previous_wakeup = -1
        self.wakeup = self.read_end = None
        self.watcher = None

    def _handle(self, number, frame):
        self.signals += 1
        if self.signals > 1:
            raise KeyboardInterrupt
        self.requested = True

    def _watch(self, descriptor):
        while True:
            received = os.read(descriptor, 64)
            if not received:  # closed on exit
                return
            if any(number in STOP_SIGNALS for number in received):
                self.request_stop()

    def is_set(self):
        """True once a signal asked this process to stop."""
        return self.requested

    def announce_once(self):
        """Call the announcement if a stop was requested and it has not been called (any thread)."""
        with self.lock:
            if self.requested and self.announcement is not None and not self.announced:
                self.announced = True
                self.announcement()

    def request_stop(self, announcement=None):
        """Record a stop request and announce it once (with ``announcement`` if none was set)."""
        with self.lock:
            self.requested = True
            self.announcement = self.announcement or announcement
        self.announce_once()

    def replace_unless_stopped(self, replacements, then=None):
        """Rename finished temporaries over their files and run ``then()``, unless a stop was requested.

        ``replacements``: deferred :class:`roughpetsc.store.outputs.atomic_path` objects. A request comes wholly
        before (the temporaries are removed) or wholly after. Returns True if the files were replaced.
        """
        try:
            with self.lock:
                replaced = not self.requested
                if replaced:
                    for replacement in replacements:
                        replacement.rename()
                    if then is not None:
                        then()
        finally:
            for replacement in replacements:
                replacement.discard()  # those not renamed
        if replaced:
            for replacement in replacements:
                replacement.sync_folder()
        return replaced

    def __enter__(self):
        for number in STOP_SIGNALS:
            self.previous[number] = signal.signal(number, self._handle)
        self.read_end, self.wakeup = os.pipe()
        os.set_blocking(self.wakeup, False)
        self.previous_wakeup = signal.set_wakeup_fd(self.wakeup, warn_on_full_buffer=False)
        self.watcher = threading.Thread(target=self._watch, args=(self.read_end,), name="stop-requests", daemon=True)
        self.watcher.start()
        return self

    def __exit__(self, *exception):
        signal.set_wakeup_fd(self.previous_wakeup)
        for number, handler in self.previous.items():
            signal.signal(number, handler)
        os.close(self.wakeup)
        self.watcher.join()
        os.close(self.read_end)
        return False


def agreed(comm, flag):
    """``flag`` of any rank of ``comm`` (mpi4py), on every rank: collective."""
    return bool(flag) if comm is None else bool(allmax(comm, [bool(flag)])[0])
