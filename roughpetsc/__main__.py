"""``python -m roughpetsc``: see :mod:`roughpetsc.cli`."""

import os
import sys

try:  # importing the modes takes a moment: Ctrl-C then ends in one line too
    from .app.cli import main
except KeyboardInterrupt:
    if os.environ.get("OMPI_COMM_WORLD_RANK", os.environ.get("PMI_RANK", "0")) == "0":
        print("roughpetsc: interrupted", file=sys.stderr, flush=True)
    sys.exit(130)

sys.exit(main())
