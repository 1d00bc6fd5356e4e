"""bladedamp.precompile (issue 15, item 5): the numba compile cost moved out of the first call.

The slow test is the claim itself: on an empty cache, after ``precompile`` in one process, a
new process running the real workloads (the reference FRFs of both dampers with the default
harmonics, a 16-blade mistuned FRF on its sparse Jacobian, the time integrations, the
monodromy of the oscillator and of a disk) compiles no kernel of bladedamp: numba's own counters of every
dispatcher (``stats.cache_misses``) stay empty. Without precompile the same process misses
(checked in the same test, so the counter is shown able to fail).
"""
from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

import bladedamp as bd
from bladedamp import cli

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")

HEADER = """
import json, sys, warnings
import numpy as np
import bladedamp as bd
from bladedamp.hbm.stability import with_stability
warnings.simplefilter("ignore")
"""
OSCILLATOR = """
osc = bd.FrictionOscillator(mass=1.0, stiffness=1.0, damping=0.01, contact_stiffness=1.0,
                            friction_coefficient=1.0, normal_load=0.1, forcing=0.05)
r = osc.frequency_response(0.1, 0.2)
"""
THE_REST = """
osc.time_response([0.16], max_periods=30)
with_stability(osc, r, method="monodromy")
disk = bd.reference_disk("cylinder", 1e-3)
disk.frequency_response(94, 96)
bd.reference_disk("wedge", 0.3e-3).frequency_response(94, 96)
m = bd.MistunedDisk.from_tuned(disk, kappa=1 + 0.02 * np.random.default_rng(0).standard_normal(16))
r = m.frequency_response(94.5, 95, harmonics=(0, 1, 2, 3, 4, 5), max_step=0.2)
assert not m.hbm_system((0, 1, 2, 3, 4, 5)).dense          # the sparse path was taken
m.time_response([95.0], max_periods=2, min_periods=1)
from bladedamp.hbm.monodromy import monodromy_multipliers
import dataclasses
four = dataclasses.replace(bd.reference_disk("cylinder", 1e-3), n_blades=4)
r = four.frequency_response(93, 93.5, harmonics=(0, 1, 2, 3))
monodromy_multipliers(four, r.coefficients[-1], r.basis, float(r.omega[-1]))
"""
MISSES = """
from numba.core.registry import CPUDispatcher
missed = sorted(f"{name}.{attr}" for name, mod in list(sys.modules.items()) if name.startswith("bladedamp")
                for attr, obj in vars(mod).items()
                if isinstance(obj, CPUDispatcher) and obj.__module__ == name and obj.stats.cache_misses)
print(json.dumps(missed))
"""


def run(code, cache):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=ROOT)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert out.returncode == 0, out.stderr[-3000:]
    return (out.stdout.strip().splitlines() or [""])[-1]


@pytest.mark.slow
def test_after_precompile_a_new_process_compiles_nothing(tmp_path):
    # on an empty cache the oscillator's FRF alone compiles the point's return map (since the
    # fused point_contact_harmonics kernel, through _point_return_map): the counter can fail
    missed = json.loads(run(HEADER + OSCILLATOR + MISSES, tmp_path / "cold"))
    assert "bladedamp.contact.point._point_return_map" in missed, missed
    run("import bladedamp; bladedamp.precompile(None)", tmp_path / "pre")
    assert json.loads(run(HEADER + OSCILLATOR + THE_REST + MISSES, tmp_path / "pre")) == []


def test_precompile_reports_each_group_and_the_cli_runs_it(capsys):
    lines = []
    seconds = bd.precompile(progress=lines.append)
    assert set(seconds) == {"oscillator", "disk"} and all(s > 0 for s in seconds.values())
    assert [line.split()[0] for line in lines] == ["oscillator", "disk"]
    assert cli.main(["precompile"]) == 0
    err = capsys.readouterr().err
    assert "disk kernels ready" in err and "later processes only load them" in err


def _cold(xdg, code=""):
    """In a new process on the per-user cache under ``xdg`` (XDG_CACHE_HOME, no NUMBA_CACHE_DIR):
    ``code``, then cache_is_cold() and what the CLI's compile notice prints."""
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(XDG_CACHE_HOME=str(xdg), PYTHONPATH=ROOT)
    probe = (code + "\nimport io\nfrom bladedamp.compilation import cache_is_cold\nfrom bladedamp.cli import Progress\n"
             "s = io.StringIO(); Progress(s).compiling(); print(cache_is_cold(), repr(s.getvalue()))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, env=env)
    assert out.returncode == 0, out.stderr[-3000:]
    return out.stdout.strip().splitlines()[-1]


def test_a_cold_cache_is_detected_and_announced_once(tmp_path):
    """An empty per-user cache (XDG_CACHE_HOME a new folder) is cold and the commands say so in
    one line; once numba has written one kernel of bladedamp there (a real compile, of the
    smallest kernel) it is not, and they say nothing."""
    from bladedamp.compilation import COLD_COMPILE_SECONDS

    cold = _cold(tmp_path)
    assert cold.startswith("True ") and cold.count("\\n") == 1, cold
    assert f"compiling kernels once, about {COLD_COMPILE_SECONDS} s; `bladedamp precompile` does it ahead" in cold
    warm = _cold(tmp_path, "import numpy as np\nfrom bladedamp.hbm.linsolve import permutation_sign\n"
                           "permutation_sign(np.arange(3))")
    assert warm == "False ''", warm
    assert list((tmp_path / "bladedamp" / "numba").glob("*/*.nbi"))      # numba wrote it where we looked
