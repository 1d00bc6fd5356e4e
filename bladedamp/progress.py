"""Progress bars of the studies and the command line: one bar, drawn by ``tqdm.auto`` (a widget in
Jupyter, a text bar in a terminal).

A study's ``progress`` option is ``True`` (draw a bar), ``False`` / ``None`` (nothing) or a
callable ``(done, total)`` (or ``(done, total, message)`` where the study says so) called as its
cases finish; :func:`progress_callback` turns that option into the callable the study calls.
"""
from __future__ import annotations

import sys
import time


class ProgressBar:
    """A ``(done, total[, message])`` callback drawn as a ``tqdm.auto`` bar titled ``description``.

    The bar is made at the first call (when ``total`` is known), its clock started when this
    object was (the study's start), and closed when ``done`` reaches ``total``. ``file``: the stream of a text bar (default stderr; a Jupyter widget has its own
    place); ``disable``: no bar at all (``None``: none when ``file`` is not a terminal, tqdm's
    rule); ``leave``: keep the finished bar on screen."""

    def __init__(self, description: str, file=None, disable: bool | None = False, leave: bool = True):
        self.description = description
        self.file = file
        self.disable = disable
        self.leave = leave
        self.bar = None
        self.started = time.time()          # the bar's clock (tqdm's start_t, on time.time)

    def __call__(self, done: int, total: int, message: str | None = None) -> None:
        if self.bar is None:
            from tqdm.auto import tqdm

            self.bar = tqdm(total=total, desc=self.description, file=self.file if self.file is not None else sys.stderr,
                            disable=self.disable, leave=self.leave)
            self.bar.start_t = self.started
        self.bar.n = done
        if message:
            self.bar.set_postfix_str(message, refresh=False)
        self.bar.refresh()
        if done >= total:
            self.bar.close()
            self.bar = None


def progress_callback(progress, description: str):
    """The callable a study calls as its cases finish, from its ``progress`` option: a
    :class:`ProgressBar` titled ``description`` for ``True``, None for ``False`` or ``None``, the
    callable itself otherwise; ValueError for anything else."""
    if progress is None or progress is False:
        return None
    if progress is True:
        return ProgressBar(description)
    if callable(progress):
        return progress
    raise ValueError(f"progress must be True, False, None or a callable (done, total) (got {progress!r})")
