"""Where numba keeps the compiled kernels of bladedamp: a per-user cache, never the package.

numba's default (``cache=True``) writes ``*.nbi`` / ``*.nbc`` files into ``__pycache__`` next
to the source when that folder is writable, i.e. into ``site-packages/bladedamp`` after
``pip install .``. ``pip uninstall`` (run by ``pip install -e .`` over it) does not know those
files and leaves them behind, and the folder they keep alive turns ``bladedamp`` into an empty
namespace package that shadows the editable install. So unless the user chose a cache folder
(``NUMBA_CACHE_DIR``), the kernels go to ``$XDG_CACHE_HOME/bladedamp/numba`` (default
``~/.cache/bladedamp/numba``), or to the temporary folder if that is not writable. numba names
each source file's sub-folder after its full path, so an installed and an editable copy never
share compiled code. Must run before the first ``@njit(cache=True)`` of the package is
decorated: numba reads ``config.CACHE_DIR`` at decoration time.
"""
from __future__ import annotations

import os
import tempfile


def user_cache_dir() -> str:
    """The per-user folder for bladedamp's numba cache (not created here)."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "bladedamp", "numba")


def _writable(path: str) -> bool:
    try:
        os.makedirs(path, exist_ok=True)
        with tempfile.TemporaryFile(dir=path):
            pass
        return True
    except OSError:
        return False


def configure() -> str | None:
    """Point numba's cache at the per-user folder unless ``NUMBA_CACHE_DIR`` is set; returns
    the folder in use (None: numba's own choice, the user's setting).

    Does not import numba (0.5-1 s): if numba is not loaded yet, the folder is given through
    ``NUMBA_CACHE_DIR``, which numba reads when it is first imported (and which worker
    processes inherit); if it is, through ``numba.config.CACHE_DIR``."""
    import sys

    if os.environ.get("NUMBA_CACHE_DIR"):
        return None
    for path in (user_cache_dir(), os.path.join(tempfile.gettempdir(), f"bladedamp-numba-{os.getuid()}")):
        if _writable(path):
            if "numba" in sys.modules:
                from numba.core import config

                config.CACHE_DIR = path
            else:
                os.environ["NUMBA_CACHE_DIR"] = path
            return path
    return None
