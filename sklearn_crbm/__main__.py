"""``python -m sklearn_crbm``: see :mod:`sklearn_crbm._cli`."""

import sys

from ._cli import main

if __name__ == "__main__":
    sys.exit(main())
