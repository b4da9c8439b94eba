"""``python -m poinsot``: the command line, as the ``poinsot`` script."""

import sys

try:
    from .app.cli import main
except KeyboardInterrupt:  # Ctrl-C in the milliseconds before main() installs its handler
    sys.exit(130)

if __name__ == "__main__":
    sys.exit(main())
