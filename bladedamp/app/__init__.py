"""The damper-design dashboard: a teaching app served by Voila (``bladedamp app``).

:class:`Dashboard` holds the controls (ipywidgets: damper type, mass, engine order, friction
coefficient, tip excitation) and the views: the frequency response with and without the damper
(matplotlib), and the 3D contact view with the hysteresis loop of a picked contact point
(:func:`bladedamp.viz.notebook3d.contact_view`) at the resonance. Every change of a control
recomputes the reference disk's response (:class:`bladedamp.viz.widgets.DiskFRFCache`: the
library's own peak search at a coarse continuation step, memoised, so a control moved back
answers at once) and redraws the views; a status line says what is being computed and, after,
the peak, the reduction and the accuracy of the one-harmonic balance.

The notebook ``dashboard.ipynb`` beside this module shows ``Dashboard().widget``;
:func:`serve` runs Voila on it (the command ``bladedamp app``).

Units: SI inside; the controls carry theirs in their labels (g, N).
"""
from __future__ import annotations

import socket
import sys
from pathlib import Path

import numpy as np

#: the dashboard notebook shipped with the package
NOTEBOOK = Path(__file__).with_name("dashboard.ipynb")
#: the continuation step of the dashboard's responses (see DiskFRFCache: peaks within 0.1 % of
#: the studies' step 0.05, about a second per new response)
DASHBOARD_MAX_STEP = 0.2
#: the continuation step of the damper-free (linear) responses: fine enough for a smooth
#: resonance curve, cheap because linear (memoised per engine order and excitation)
UNDAMPED_MAX_STEP = 0.05

DAMPER_CHOICES = (("cylinder", "cylinder"), ("wedge", "wedge"), ("no damper", None))


def frf_figure(damped, undamped, title: str):
    """The frequency response figure of the dashboard: tip amplitude u_x [mm] over the
    excitation frequency [Hz] of ``damped`` (a :class:`~bladedamp.viz.widgets.DiskFRF`, None
    for no damper) with its peak marked, and ``undamped`` dashed; a log amplitude axis when the
    damped peak is below a quarter of the undamped one (both stay readable).
    ``fig.data = (damped, undamped)``."""
    import matplotlib.pyplot as plt

    from .. import palette

    fig, ax = plt.subplots(figsize=(7.2, 4.2))
    ax.plot(undamped.frequency_hz, 1e3 * undamped.tip_amplitude[:, 0], color=palette.UNDAMPED, ls="--", lw=1.2,
            label="no damper")
    if damped is not None:
        kind = damped.disk.damper.kind
        colour = palette.DAMPER.get(kind, palette.series(0))
        ax.plot(damped.frequency_hz, 1e3 * damped.tip_amplitude[:, 0], color=colour, lw=1.8,
                label=f"{kind} {1e3 * damped.disk.damper.mass:.3g} g")
        ax.plot([damped.peak_frequency_hz], [1e3 * damped.peak_amplitude], "o", ms=7, mfc="none", mec=colour, mew=1.6,
                label="_peak")
        if damped.peak_amplitude < 0.25 * undamped.peak_amplitude:
            ax.set_yscale("log")
    ax.set_xlabel("excitation frequency [Hz]")
    ax.set_ylabel("tip amplitude u_x [mm]")
    ax.grid(True, which="both", alpha=0.3)
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=9, loc="upper left")
    fig.tight_layout()
    fig.data = (damped, undamped)
    return fig


class Dashboard:
    """Controls and views of the damper-design dashboard (see the module docstring).

    ``widget`` is the whole dashboard (an ipywidgets box); ``values()`` the controls' values in
    SI; ``figure_data`` the (damped, undamped) DiskFRF shown now (the undamped at
    UNDAMPED_MAX_STEP); ``view_3d``: the 3D contact view
    shown from the start (its checkbox ``show_3d`` turns it on and off; the page is about 2 MB,
    so it starts off and the first page loads with the frequency response alone). ``cache``: a
    DiskFRFCache (default: a new one at DASHBOARD_MAX_STEP).
    """

    def __init__(self, cache=None, view_3d: bool = False):
        import ipywidgets as w

        from ..viz.widgets import DiskFRFCache

        self.cache = cache if cache is not None else DiskFRFCache(max_step=DASHBOARD_MAX_STEP)
        self.undamped_cache = DiskFRFCache(self.cache.f_range_hz, max_step=UNDAMPED_MAX_STEP)
        style, layout = {"description_width": "11em"}, w.Layout(width="26em")
        self.damper = w.Dropdown(options=DAMPER_CHOICES, value="cylinder", description="damper type",
                                 style=style, layout=layout)
        self.mass = w.FloatLogSlider(value=1.0, base=10, min=-1, max=1, step=0.05, description="damper mass [g]",
                                     readout_format=".3g", continuous_update=False, style=style, layout=layout)
        self.engine_order = w.IntSlider(value=1, min=0, max=8, description="engine order",
                                        continuous_update=False, style=style, layout=layout)
        self.friction = w.FloatSlider(value=0.3, min=0.05, max=1.0, step=0.05, description="friction coefficient",
                                      readout_format=".2f", continuous_update=False, style=style, layout=layout)
        self.excitation = w.FloatLogSlider(value=0.1, base=10, min=-2, max=0, step=0.05,
                                           description="tip excitation F_x [N]", readout_format=".3g",
                                           continuous_update=False, style=style, layout=layout)
        self.controls = (self.damper, self.mass, self.engine_order, self.friction, self.excitation)
        for control in self.controls:
            control.observe(self.update, names="value")
        self.show_3d = w.Checkbox(value=bool(view_3d), description="3D contact view and hysteresis loop",
                                  indent=False, layout=layout)
        self.show_3d.observe(self.update, names="value")
        self.status = w.HTML(layout=w.Layout(width="26em"))
        self.status.add_class("bd-status")
        self.frf_view = w.Output(layout=w.Layout(width="46em", min_height="26em"))
        self.frf_view.add_class("bd-frf")
        self.contact_view = w.Output(layout=w.Layout(width="100%"))
        self.contact_view.add_class("bd-contact")
        intro = w.HTML("Move a control and the frequency response of the "
                       "16-blade reference disk is computed again (about a second; a value seen before answers "
                       "at once). Tick the 3D view to see, below, the contact state at the resonance on the "
                       "damper and platform faces and the hysteresis loop of a contact point.", layout=w.Layout(width="26em"))
        self.widget = w.VBox([w.HBox([w.VBox([intro, *self.controls, self.show_3d, self.status]), self.frf_view]),
                              self.contact_view])
        self.figure_data = None
        self.update()

    def values(self) -> dict:
        """The controls in SI: kind (None: no damper), mass [kg], engine_order, friction_coefficient
        [-], excitation (6,) tip load [N, N m]."""
        return {"kind": self.damper.value, "mass": 1e-3 * float(self.mass.value),
                "engine_order": int(self.engine_order.value), "friction_coefficient": float(self.friction.value),
                "excitation": (float(self.excitation.value), 0.0, 0.0, 0.0, 0.0, 0.0)}

    def _say(self, text: str, busy: bool = False):
        colour = "#8a5a00" if busy else "#111"
        self.status.value = f'<div style="color: {colour}">{text}</div>'

    def update(self, *_):
        """Compute the response for the controls' values and redraw the views."""
        import matplotlib.pyplot as plt
        from IPython.display import display

        v = self.values()
        self._say("computing the frequency response ...", busy=True)
        free = self.undamped_cache.response(None, 0.0, v["engine_order"], excitation=v["excitation"])
        damped = None
        if v["kind"] is not None:
            damped = self.cache.response(v["kind"], v["mass"], v["engine_order"], excitation=v["excitation"],
                                         friction_coefficient=v["friction_coefficient"])
        what = "no damper" if damped is None else \
            f"{v['kind']} damper {1e3 * v['mass']:.3g} g, mu = {v['friction_coefficient']:.2f}"
        title = f"reference disk, {what}, EO = {v['engine_order']}, F_x = {v['excitation'][0]:.3g} N"
        fig = frf_figure(damped, free, title)
        self.figure_data = fig.data
        with self.frf_view:
            self.frf_view.clear_output(wait=True)
            display(fig)
        plt.close(fig)
        self._say(self.summary(damped, free))
        self.contact_view.clear_output()
        if self.show_3d.value and damped is not None and len(damped.response.omega):
            self._say(self.summary(damped, free) + "<br>drawing the 3D contact view ...", busy=True)
            from ..viz.notebook3d import contact_view

            with self.contact_view:
                display(contact_view(damped.response, height=520, n_frames=24))
            self._say(self.summary(damped, free))

    @staticmethod
    def summary(damped, free) -> str:
        """The status line after a computation: the peak, the reduction, the accuracy in words."""
        if damped is None:
            return (f"no damper: peak {1e3 * free.peak_amplitude:.3f} mm at {free.peak_frequency_hz:.2f} Hz "
                    "(linear, exact with one harmonic)")
        text = (f"peak {1e3 * damped.peak_amplitude:.3f} mm at {damped.peak_frequency_hz:.2f} Hz, "
                f"reduction {100 * damped.reduction(free):.1f} % against no damper ({damped.seconds:.1f} s)")
        if damped.method == "incomplete":
            text += (f"<br>{damped.response.status_message} The peak shown is the largest converged point, a lower "
                     "bound.")
        error = float(getattr(damped.response, "harmonic_error", np.nan))
        if np.isfinite(error):
            text += (f"<br>one-harmonic balance (the paper's setting): its peak may be off by about "
                     f"{100 * error:.1f} % (the estimated harmonic error)" + ("" if error <= 0.05 else "; for a design decision run "
                                              "bladedamp frf with harmonics = \"auto\""))
        return text


def dashboard(**options):
    """Show the dashboard in the notebook (``Dashboard(**options).widget``); returns the Dashboard."""
    from IPython.display import display

    board = Dashboard(**options)
    display(board.widget)
    return board


def free_port(host: str = "127.0.0.1") -> int:
    """A TCP port free on ``host`` now (the system's choice)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return int(s.getsockname()[1])


def port_in_use(port: int, host: str = "127.0.0.1") -> bool:
    """Whether ``port`` on ``host`` cannot be bound now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        try:
            s.bind((host, port))
        except OSError:
            return True
    return False


def voila_command(port: int, host: str = "127.0.0.1") -> list[str]:
    """The command that serves the dashboard notebook with Voila on ``host``:``port`` (no browser)."""
    return [sys.executable, "-m", "voila", str(NOTEBOOK), f"--port={int(port)}", "--no-browser",
            f"--Voila.ip={host}", "--Voila.log_level=WARN", "--show_tracebacks=False"]


def wait_for_port(port: int, timeout: float, host: str = "127.0.0.1", process=None) -> bool:
    """Whether ``host``:``port`` accepts connections within ``timeout`` seconds (False at once if
    ``process``, a Popen, ends before)."""
    import time

    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if process is not None and process.poll() is not None:
            return False
        try:
            with socket.create_connection((host, port), timeout=0.5):
                return True
        except OSError:
            time.sleep(0.2)
    return False
