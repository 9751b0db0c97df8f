"""FFTW planning: the planner effort and the wisdom that makes a run repeatable.

Wisdom cache ``-fft_wisdom``; ``ROUGHPETSC_FFT_EFFORT`` and ``ROUGHPETSC_FFT_WISDOM`` in the environment
override the effort and the cache. Why, and what it costs: docs/runtime.md.
"""

from contextlib import contextmanager
import base64
import json
import os
import platform
import re

from ..errors import ParameterError, UserError

EFFORTS = ("FFTW_ESTIMATE", "FFTW_MEASURE", "FFTW_PATIENT", "FFTW_EXHAUSTIVE")
EFFORT_VARIABLE = "ROUGHPETSC_FFT_EFFORT"
WISDOM_VARIABLE = "ROUGHPETSC_FFT_WISDOM"


def planner_effort(effort):
    """The planner flag to use for a requested ``effort``: the environment's override, if set.

    Raises
    ------
    ParameterError
        (parameter ``effort``) if the effort (or the override) is not an FFTW planner flag.
    """
    forced = os.environ.get(EFFORT_VARIABLE, "").strip()
    if forced:
        forced = forced.upper() if forced.upper().startswith("FFTW_") else "FFTW_" + forced.upper()
        if forced not in EFFORTS:
            raise ParameterError("effort", f"{EFFORT_VARIABLE}={os.environ[EFFORT_VARIABLE]}: not a planner "
                                           f"effort (one of {', '.join(EFFORTS)})")
        return forced
    if effort not in EFFORTS:
        raise ParameterError("effort", f"unknown planner effort '{effort}' (one of {', '.join(EFFORTS)})")
    return effort


def _cpu_model():
    try:
        with open("/proc/cpuinfo") as cpuinfo:
            for line in cpuinfo:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def default_wisdom_path():
    """The cache file of this machine's CPU model (plans measured on one CPU are not the best on another)."""
    folder = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    model = re.sub(r"[^A-Za-z0-9]+", "-", _cpu_model()).strip("-").lower() or "cpu"
    return os.path.join(folder, "roughpetsc", f"fftw-wisdom-{model}.json")


def wisdom_path(option_value):
    """The cache file to use: the environment's override, else ``-fft_wisdom``, else the default; None for none."""
    value = os.environ.get(WISDOM_VARIABLE, "").strip() or (option_value or "").strip()
    if value.lower() == "none":
        return None
    return value or default_wisdom_path()


def check_wisdom_path(option_value, option):
    """Refuse, naming ``-option``, a wisdom file given in a folder that does not exist, a folder, or a file that
    holds something else than wisdom.

    Such a path would otherwise be skipped silently, and every run would measure its plans again; a file of
    something else would be replaced by the wisdom. An empty file is a cache yet to be filled.
    """
    value = (option_value or "").strip()
    if not value or value.lower() == "none":
        return
    if os.path.isdir(value):
        raise UserError(f"-{option} {value}: is a folder; give a file name (or none)")
    folder = os.path.dirname(os.path.abspath(value))
    if not os.path.isdir(folder):
        raise UserError(f"-{option} {value}: the folder {folder} does not exist")
    if os.path.isfile(value) and os.path.getsize(value) > 0:
        try:
            with open(value) as f:
                items = json.loads(f.read())
            if not (isinstance(items, list) and all(isinstance(item, str) for item in items)):
                raise ValueError("not a list of strings")
            for item in items:
                base64.b64decode(item, validate=True)
        except (OSError, ValueError):
            raise UserError(f"-{option} {value}: not an FFTW wisdom file of roughpetsc; give another file name "
                            "(or none)") from None


def decode_wisdom(text):
    """FFTW wisdom from its text form (JSON of base64 strings; :func:`encode_wisdom`)."""
    return tuple(base64.b64decode(item) for item in json.loads(text))


def encode_wisdom(wisdom):
    return json.dumps([base64.b64encode(item).decode() for item in wisdom])


@contextmanager
def remembered_plans(comm, path, effort):
    """Plans made inside the block come from (and go to) the wisdom file ``path``.

    Every rank imports rank 0's wisdom; afterwards rank 0 merges every rank's and writes it back atomically
    if planning added to it (a cache that cannot be written is skipped). Nothing happens for ESTIMATE plans.

    Parameters
    ----------
    comm : mpi4py.MPI.Comm
    path : str or None
        The wisdom file; None: no file.
    effort : str
        The planner flag the block will use (after :func:`planner_effort`).
    """
    import pyfftw

    if path is None or effort == "FFTW_ESTIMATE":
        yield
        return
    stored = None
    if comm.Get_rank() == 0 and os.path.exists(path):
        try:
            with open(path) as f:
                stored = f.read()
            decode_wisdom(stored)
        except (OSError, ValueError):
            stored = None  # a damaged cache is measured anew
    stored = comm.bcast(stored, root=0)
    if stored:
        pyfftw.import_wisdom(decode_wisdom(stored))
    yield
    # Ranks of an uneven decomposition plan other shapes than rank 0: every rank's plans are kept.
    everyone = comm.gather(encode_wisdom(pyfftw.export_wisdom()), root=0)
    if comm.Get_rank() == 0:
        for wisdom in everyone[1:]:
            pyfftw.import_wisdom(decode_wisdom(wisdom))
        wisdom = encode_wisdom(pyfftw.export_wisdom())
        if wisdom != stored:
            _write_quietly(path, wisdom)


def _write_quietly(path, text):
    folder = os.path.dirname(os.path.abspath(path))
    temporary = f"{path}.{os.getpid()}.tmp"
    try:
        os.makedirs(folder, exist_ok=True)
        with open(temporary, "w") as f:
            f.write(text)
        os.replace(temporary, path)
    except OSError:
        try:
            os.remove(temporary)
        except OSError:
            pass
