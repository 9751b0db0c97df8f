"""Where the standard output goes: a person at a terminal, a pipe or a file, also under ``mpiexec``.

Under ``mpiexec`` every rank gets a pseudo-terminal, so the launcher's own standard output decides whether a
person watches (:func:`watched`). :class:`ClosedPipeTolerant` lets the run go on after ``| head`` closes the pipe.
"""

import io
import os
import sys

# Environment variables that launchers set in the processes they start (Open MPI, PMIx, MPICH's Hydra).
LAUNCHER_VARIABLES = ("OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE")
# Process names of the launchers whose standard output receives the ranks' output.
LAUNCHER_NAMES = ("mpiexec", "mpirun", "orterun", "prterun", "mpiexec.hydra", "mpiexec.openmpi", "mpirun.openmpi",
                  "mpiexec.mpich", "mpirun.mpich")


def printer(quiet, comm):
    """``say(text)``: print on rank 0 unless ``quiet``."""
    def say(text):
        if not quiet and comm.Get_rank() == 0:
            print(text, flush=True)
    return say


def under_launcher(environ=os.environ):
    """True when this process was started by an MPI launcher."""
    return any(name in environ for name in LAUNCHER_VARIABLES)


def launcher_rank():
    """This process's MPI rank as the launcher tells it (MPI is not initialised yet); 0 if not under mpiexec."""
    for name in ("OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"):
        if os.environ.get(name, "").isdigit():
            return int(os.environ[name])
    return 0


def _parent(pid):
    """``(name, parent pid)`` of process ``pid`` from /proc, or None where it cannot be read."""
    try:
        with open(f"/proc/{pid}/stat") as stat:
            text = stat.read()
    except OSError:
        return None
    name = text[text.index("(") + 1:text.rindex(")")]
    return name, int(text[text.rindex(")") + 2:].split()[1])


def launcher_pid(pid=None):
    """The process id of the launcher among this process's ancestors, or None if none is found."""
    pid = os.getppid() if pid is None else pid
    for _ in range(16):  # mpiexec -> (orted, hydra_pmi_proxy) -> rank: a few levels at most
        found = _parent(pid)
        if found is None:
            return None
        name, parent = found
        if name in LAUNCHER_NAMES or name.startswith(("mpiexec", "mpirun")):
            return pid
        if parent <= 1:
            return None
        pid = parent
    return None


def is_terminal_path(path):
    """True for a terminal device (``/dev/pts/N``, ``/dev/ttyN``, ``/dev/tty``)."""
    return path.startswith(("/dev/pts/", "/dev/tty"))


def watched(stream=None):
    """True when a person is likely to read ``stream`` (default ``sys.stdout``) as it is printed.

    The stream is a terminal, and under a launcher so is the launcher's standard output (from ``/proc``); False
    where that cannot be read: progress must not end up in a redirected log.
    """
    stream = sys.stdout if stream is None else stream
    try:
        if not stream.isatty():
            return False
    except (AttributeError, ValueError, OSError):
        return False
    if not under_launcher():
        return True
    pid = launcher_pid()
    if pid is None:
        return False
    try:
        return is_terminal_path(os.readlink(f"/proc/{pid}/fd/1"))
    except OSError:
        return False


class ClosedPipeTolerant(io.TextIOBase):
    """A text stream that drops what it is given once its reader has gone (``BrokenPipeError``)."""

    def __init__(self, stream):
        super().__init__()
        self.stream = stream
        self.closed_by_reader = False

    def write(self, text):
        if not self.closed_by_reader:
            try:
                self.stream.write(text)
            except BrokenPipeError:
                self._reader_gone()
        return len(text)

    def flush(self):
        if not self.closed_by_reader:
            try:
                self.stream.flush()
            except BrokenPipeError:
                self._reader_gone()

    def _reader_gone(self):
        self.closed_by_reader = True
        try:  # what is left in the buffer would fail again when Python flushes it at exit
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, self.stream.fileno())
            os.close(devnull)
        except (OSError, ValueError):
            pass

    def isatty(self):
        return not self.closed_by_reader and self.stream.isatty()

    def fileno(self):
        return self.stream.fileno()

    @property
    def encoding(self):
        return self.stream.encoding
