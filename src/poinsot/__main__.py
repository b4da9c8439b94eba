"""``python -m poinsot``: the command line, as the ``poinsot`` script."""

import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
