"""Slider moves of the disk widgets (bladedamp.viz.widgets), new against a saved copy of the old ones.

    python benchmarks/bench_widgets.py OLD_WIDGETS.py

OLD_WIDGETS.py: the previous widgets module with absolute imports (e.g. ``git show
38990fe:bladedamp/viz/widgets.py`` with ``from ..`` replaced by ``from bladedamp.``). Both run
in one process, interleaved, on the same sequence of slider values (first value cold, then
neighbouring masses, then platform angles), so their ratio is meaningful on a loaded machine.
"""
import importlib.util
import sys
import time
import warnings

warnings.simplefilter("ignore")

from bladedamp.viz import widgets as new  # noqa: E402


def load(path):
    spec = importlib.util.spec_from_file_location("old_widgets", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules["old_widgets"] = mod
    spec.loader.exec_module(mod)
    return mod


def main(old_path):
    old = load(old_path)
    caches = {"old": old.DiskFRFCache(), "new": new.DiskFRFCache()}
    mods = {"old": old, "new": new}
    masses = (1.0, 1.1, 1.2, 0.8, 2.0, 0.5)
    total = {"old": 0.0, "new": 0.0}
    print("move                old [s]   new [s]   new/old   peak old [mm]  peak new [mm]")
    for m in masses:
        row = {}
        for k in ("old", "new"):
            t = time.perf_counter()
            r = mods[k].disk_frf("cylinder", m, cache=caches[k])
            row[k] = (time.perf_counter() - t, r.peak_amplitude)
            total[k] += row[k][0]
        print(f"mass {m:4.1f} g         {row['old'][0]:7.3f}   {row['new'][0]:7.3f}   {row['new'][0] / row['old'][0]:7.2f}"
              f"   {1e3 * row['old'][1]:.5f}        {1e3 * row['new'][1]:.5f}")
    for g in (45.0, 55.0, 70.0):
        row = {}
        for k in ("old", "new"):
            t = time.perf_counter()
            fig = mods[k].platform_angle_figure(g, "cylinder", 1.0, cache=caches[k])
            row[k] = time.perf_counter() - t
            total[k] += row[k]
            import matplotlib.pyplot as plt
            plt.close(fig)
        print(f"gamma_R {g:4.1f} deg      {row['old']:7.3f}   {row['new']:7.3f}   {row['new'] / row['old']:7.2f}")
    t = time.perf_counter()
    new.disk_frf("cylinder", 1.1, cache=caches["new"])
    print(f"memoised move (new): {1e3 * (time.perf_counter() - t):.2f} ms")
    print(f"total: old {total['old']:.2f} s, new {total['new']:.2f} s, ratio {total['new'] / total['old']:.2f}")


if __name__ == "__main__":
    import matplotlib

    matplotlib.use("Agg")
    main(sys.argv[1])
