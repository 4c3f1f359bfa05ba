"""``python -m sklearn_crbm``: see :mod:`sklearn_crbm.cli`."""

import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
