"""``python -m poinsot``: the command line, as the ``poinsot`` script."""

import sys

from .app.cli import main

if __name__ == "__main__":
    sys.exit(main())
