"""The command line, ``python -m sklearn_crbm``, and its demos.

:func:`main` parses the commands (:mod:`._options`) and runs them
(:mod:`._main`); the demo of generation and fill-in is :mod:`._demo`, the
styles command :mod:`._style_demo`.  Everything they measure or generate is
done by the library.
"""

from ._main import main

__all__ = ["main"]
