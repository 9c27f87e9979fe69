"""Figures of the contact benchmarks against closed forms (Hertz, Cattaneo-Mindlin: ``vemkit.studies.hertz``,
``.mindlin``), drawn from the Datasets of results/3d/hertz.nc and mindlin.nc (matplotlib's object API);
the figures of one solution are in :mod:`vemkit.report.figures`:

- :func:`hertz_pressure_figure`: p(r) / p0 against r / a of every mesh with Hertz's
  sqrt(1 - r^2 / a^2) (a, p0 Hertz's at each mesh's measured P);
- :func:`mindlin_shear_figure`: the shear traction |sigma_tau . e_z| / (mu p0) against r / a of every
  load step of one mesh with Johnson's q(r) at the measured Q / (mu P);
- :func:`mindlin_zones_figure`: stick / slip / separated at the Gamma_C vertices seen from below (the
  foundation plane x-z, the half x >= 0 mirrored), one panel per load step.
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from vemkit.report.figures import FAMILY_COLORS, STATE_COLORS


def hertz_pressure_figure(ds) -> Figure:
    """p / p0_Hertz against r / a_Hertz per mesh h, and Hertz's profile."""
    fig = Figure(figsize=(6.0, 4.2))
    ax = fig.add_subplot()
    for i, h in enumerate(ds["h"].values):
        one = ds.sel(h=h)
        r, p = one["r"].values, one["p"].values
        keep = np.isfinite(r) & (r < 1.5 * float(one["a_hertz"]))
        ax.plot(
            r[keep] / float(one["a_hertz"]),
            p[keep] / float(one["p0_hertz"]),
            ".",
            ms=3,
            color=FAMILY_COLORS[i % len(FAMILY_COLORS)],
            label=f"h = {h:g} ({int(one['dofs'])} DOFs)",
        )
    s = np.linspace(0.0, 1.0, 200)
    ax.plot(s, np.sqrt(1 - s**2), "k-", lw=1.2, label="Hertz")
    ax.set_xlabel("r / a (Hertz)")
    ax.set_ylabel("p / p0 (Hertz)")
    ax.set_title("Hertz: sphere on a stiff foundation, nodal contact pressure", fontsize=9)
    ax.legend(fontsize=8)
    return fig


def _q_mindlin(s, c_over_a):
    """Johnson's q / (mu p0) at r / a = s (``vemkit.studies.mindlin.mindlin_shear`` with a = 1)."""
    return np.sqrt(np.maximum(1 - s**2, 0.0)) - np.sqrt(np.maximum(c_over_a**2 - s**2, 0.0))


def mindlin_shear_figure(ds, h: float) -> Figure:
    """Every load step of mesh ``h``: |sigma_tau . e_z| / (mu p0) at the contact vertices against r / a,
    Johnson's q(r) at Mindlin's c."""
    one = ds.sel(h=h)
    fig = Figure(figsize=(6.4, 4.4))
    ax = fig.add_subplot()
    s = np.linspace(0.0, 1.0, 300)
    for i, shift in enumerate(one["shift"].values):
        st = one.sel(shift=shift)
        a, P, mu = float(st["a"]), float(st["P"]), float(st["mu"])
        p0 = 3 * P / (2 * math.pi * a**2)
        on = st["on"].values == 1
        color = FAMILY_COLORS[i % len(FAMILY_COLORS)]
        ax.plot(st["r"].values[on] / a, st["q"].values[on] / (mu * p0), ".", ms=3, color=color)
        ax.plot(
            s,
            _q_mindlin(s, float(st["c_mindlin"]) / a),
            "-",
            lw=1,
            color=color,
            label=f"Q/muP = {float(st['Q_over_muP']):.2f}",
        )
    ax.set_xlabel("r / a")
    ax.set_ylabel("q / (mu p0)")
    ax.set_title(f"Cattaneo-Mindlin, h = {h:g}: shear traction (dots) and Johnson's q(r) (lines)", fontsize=9)
    ax.legend(fontsize=7)
    return fig


def mindlin_zones_figure(ds, h: float) -> Figure:
    """Stick / slip / separated at the Gamma_C vertices of mesh ``h`` seen from below, per load step,
    the circles r = c measured (dashed) and Mindlin's c (solid)."""
    one = ds.sel(h=h)
    shifts = one["shift"].values
    cols = min(3, shifts.size)
    rows = math.ceil(shifts.size / cols)
    fig = Figure(figsize=(3.0 * cols, 3.0 * rows))
    angle = np.linspace(0, 2 * math.pi, 200)
    for k, shift in enumerate(shifts):
        st = one.sel(shift=shift)
        ax = fig.add_subplot(rows, cols, k + 1)
        x, z = st["x"].values, st["z"].values
        keep = np.isfinite(x)
        state = np.where(st["stick"].values == 1, 1, np.where(st["on"].values == 1, 2, 0))
        a = float(st["a"])
        near = keep & (np.hypot(x, z) < 1.4 * a)
        for code, (name, color) in STATE_COLORS.items():
            m = near & (state == code)
            ax.scatter(np.r_[z[m], z[m]], np.r_[x[m], -x[m]], s=6, c=color, label=name)
        ax.plot(float(st["c"]) * np.cos(angle), float(st["c"]) * np.sin(angle), "k--", lw=0.8)
        ax.plot(float(st["c_mindlin"]) * np.cos(angle), float(st["c_mindlin"]) * np.sin(angle), "k-", lw=0.8)
        ax.set_aspect("equal")
        ax.set_title(f"Q/muP = {float(st['Q_over_muP']):.2f}", fontsize=8)
        ax.tick_params(labelsize=6)
        if k == 0:
            ax.legend(fontsize=6, loc="lower left")
    fig.suptitle(
        f"Cattaneo-Mindlin, h = {h:g}: Gamma_C from below (z right, x up; c dashed, Mindlin solid)", fontsize=9
    )
    return fig
