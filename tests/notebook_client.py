"""Executing a notebook headless for the tests (and for re-saving the shipped notebooks), with
nbclient -- what ``jupyter nbconvert --execute`` and nbval drive.

:func:`execute_notebook` runs a notebook in a fresh ``python3`` kernel whose ``PYTHONPATH``
starts with this checkout (the kernel imports the bladedamp under test). Its client reads the
kernel's shell and IOPub sockets in one-second slices instead of one unbounded wait: a reply whose
socket wake-up was missed is then read at the next slice. Seen on this stack (ipykernel 7.4,
pyzmq 27.3, jupyter_client 8.10, nbclient 0.11): now and then the client waited for minutes
after a cell whose reply the kernel had sent (the kernel idle, the cell in its history, nothing
left in its send queue), more often after cells that display widgets (tens of ``comm_open``
messages each); with the slices such a cell ends within a second of its reply.
"""
from __future__ import annotations

import os
import pathlib
import queue
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
SLICE_S = 1.0          # [s] longest single wait on a socket


def sliced(get_msg, slice_s: float = SLICE_S):
    """``get_msg(timeout)`` of a jupyter_client async channel as repeated waits of at most
    ``slice_s`` seconds until ``timeout`` (None: no limit); raises queue.Empty at the timeout."""
    async def get(timeout=None):
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            step = slice_s if deadline is None else max(0.0, min(slice_s, deadline - time.monotonic()))
            try:
                return await get_msg(timeout=step)
            except queue.Empty:
                if deadline is not None and time.monotonic() >= deadline:
                    raise
    return get


def kernel_env() -> dict:
    """The environment of the kernel: this one, with this checkout first on PYTHONPATH."""
    path = os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH", "")) if p)
    return {**os.environ, "PYTHONPATH": path}


def execute_notebook(nb, cwd, timeout: float = 600, **client_options):
    """Executes ``nb`` (an nbformat NotebookNode, changed in place: outputs, execution counts,
    widget state) in a kernel whose working directory is ``cwd``; ``timeout`` [s] per cell.
    Returns the nbclient NotebookClient."""
    from nbclient import NotebookClient

    client = NotebookClient(nb, timeout=timeout, kernel_name="python3",
                            resources={"metadata": {"path": str(cwd)}}, **client_options)

    def read_in_slices(**_):
        for channel in (client.kc.shell_channel, client.kc.iopub_channel):
            channel.get_msg = sliced(channel.get_msg)
    client.on_notebook_start = read_in_slices
    client.execute(env=kernel_env())
    return client


def resave(path, timeout: float = 600) -> float:
    """Executes the notebook at ``path`` in its folder and saves it with its new outputs in the
    form JupyterLab writes (tests/test_notebook_files.py). Returns the wall time [s]."""
    import nbformat

    path = pathlib.Path(path)
    nb = nbformat.read(path, as_version=4)
    t0 = time.perf_counter()
    execute_notebook(nb, path.parent, timeout=timeout)
    elapsed = time.perf_counter() - t0
    path.write_text(nbformat.writes(nb) + "\n", encoding="utf-8")
    return elapsed


if __name__ == "__main__":          # python tests/notebook_client.py notebooks/01_*.ipynb ...: re-save them
    import sys

    for name in sys.argv[1:]:
        print(f"{name}: {resave(name):.0f} s", flush=True)
