"""``python -m encctl_gym``: the same command line as ``encctl-gym``."""

import sys

from .cli import main

if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
