"""Figures of the sweeps, the speed-accuracy study and the stability matrix (matplotlib's object API).

- :func:`sweep_map_figure`: one panel per quantity, a colour map over two grid dimensions (the
  other dimensions held at a chosen value); points that did not converge are crossed out;
- :func:`sweep_lines_figure`: a quantity against one grid dimension, one line per value of another;
- :func:`sweep_profiles_figure`: pressure, tangential stress and slip along Gamma_C, one line per
  value of a grid dimension;
- :func:`pareto_figure`: error against wall time and against DOFs for every run, the Pareto front;
- :func:`stability_figure`: the outcome of every (case, solver) and the worst independent check.

Each returns a ``matplotlib.figure.Figure``; save with ``vemkit.report.figures.save``. The sweep figures
read Datasets of ``vemkit.studies.sweeps.read_dataset`` (NaN where a point is not valid).
"""

from __future__ import annotations

import numpy as np
from matplotlib.colors import BoundaryNorm, ListedColormap, LogNorm
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

COLORS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#7f7f7f", "#17becf", "#bcbd22")
MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")


def _label(ds, name) -> str:
    var = ds[name]
    units = var.attrs.get("units")
    return f"{name} [{units}]" if units and units != "1" else name


def _fixed(ds, keep, select=None):
    """``ds`` with every grid dimension but ``keep`` held at ``select[dim]`` (default: its first value)."""
    select = dict(select or {})
    grid_dims = [d for d in ds["status"].dims if d not in keep]
    picks = {d: select.get(d, ds[d].values[0]) for d in grid_dims}
    held = ", ".join(f"{d} = {v}" for d, v in picks.items())
    return ds.sel(picks), held


def _value_labels(values) -> list[str]:
    return [f"{v:g}" if isinstance(v, (float, np.floating, int, np.integer)) else str(v) for v in values]


def _log_friendly(values) -> bool:
    v = np.asarray(values)
    return v.dtype.kind in "fi" and np.all(v > 0) and v.max() / v.min() >= 100.0


def _panels(count: int, width: float, height: float, per_row: int = 3):
    rows, cols = -(-count // per_row), min(count, per_row)
    fig = Figure(figsize=(width * cols, height * rows), layout="constrained")
    axes = np.atleast_1d(fig.subplots(rows, cols)).ravel()
    for ax in axes[count:]:
        ax.set_visible(False)
    return fig, axes[:count]


def sweep_map_figure(ds, x: str, y: str, quantities, select=None, title: str = "") -> Figure:
    """Colour maps of ``quantities`` over the grid dimensions x (columns) and y (rows)."""
    sub, held = _fixed(ds, (x, y), select)
    quantities = list(quantities)
    fig, axes = _panels(len(quantities), 4.6, 3.9)
    for ax, name in zip(axes, quantities):
        data = sub[name].transpose(y, x).values.astype(float)
        positive = np.isfinite(data) & (data > 0)
        norm = (
            LogNorm(data[positive].min(), data[positive].max())
            if (
                positive.any()
                and np.all(data[np.isfinite(data)] > 0)
                and data[positive].max() > 100 * data[positive].min()
            )
            else None
        )
        mesh = ax.pcolormesh(
            np.arange(data.shape[1] + 1) - 0.5,
            np.arange(data.shape[0] + 1) - 0.5,
            np.ma.masked_invalid(data),
            cmap="viridis",
            norm=norm,
            shading="flat",
        )
        fig.colorbar(mesh, ax=ax, label=_label(ds, name))
        bad = np.argwhere(sub["status"].transpose(y, x).values != 0)
        if bad.size:
            ax.plot(bad[:, 1], bad[:, 0], "x", color="red", ms=8, mew=2, label="not converged")
            ax.legend(loc="upper right", fontsize=7)
        ax.set_xticks(range(sub.sizes[x]), _value_labels(sub[x].values), rotation=60, fontsize=7)
        ax.set_yticks(range(sub.sizes[y]), _value_labels(sub[y].values), fontsize=7)
        ax.set_xlabel(x)
        ax.set_ylabel(y)
        ax.set_title(name, fontsize=9)
    fig.suptitle((title + "\n" if title else "") + (held or ""), fontsize=9)
    return fig


def sweep_lines_figure(ds, x: str, hue: str | None, quantities, select=None, title: str = "") -> Figure:
    """``quantities`` against the grid dimension x, one line per value of ``hue``."""
    keep = (x, hue) if hue else (x,)
    sub, held = _fixed(ds, keep, select)
    quantities = list(quantities)
    fig, axes = _panels(len(quantities), 4.4, 3.6)
    xs = np.asarray(sub[x].values)
    numeric = xs.dtype.kind in "fi"
    positions = xs.astype(float) if numeric else np.arange(xs.size, dtype=float)
    hues = list(sub[hue].values) if hue else [None]
    for ax, name in zip(axes, quantities):
        for k, h in enumerate(hues):
            line = sub.sel({hue: h}) if hue else sub
            bad = line["status"].values != 0
            values = np.where(bad, np.nan, line[name].values.astype(float))  # only converged points on the line
            ax.plot(
                positions,
                values,
                marker=MARKERS[k % len(MARKERS)],
                color=COLORS[k % len(COLORS)],
                ms=4,
                label=f"{hue} = {_value_labels([h])[0]}" if hue else None,
            )
            if bad.any():  # not converged: a cross at the foot of the panel
                ax.plot(
                    positions[bad],
                    np.full(bad.sum(), 0.03),
                    "x",
                    color=COLORS[k % len(COLORS)],
                    ms=7,
                    mew=2,
                    transform=ax.get_xaxis_transform(),
                    clip_on=False,
                )
        shown = sub[name].where(sub["status"] == 0).values.astype(float)
        shown = shown[np.isfinite(shown)]
        if shown.size and np.all(shown > 0) and shown.max() > 100 * shown.min():
            ax.set_yscale("log")
        if numeric and _log_friendly(xs):
            ax.set_xscale("log")
        elif numeric and np.all(xs >= 0) and xs.max() > 100 * max(np.min(xs[xs > 0], initial=xs.max()), 1e-300):
            threshold = float(np.min(xs[xs > 0]))  # a zero among positive values over decades: symlog
            ax.set_xscale("symlog", linthresh=threshold)
            ax.set_xlim(-0.3 * threshold, 1.5 * float(xs.max()))
        if not numeric:
            ax.set_xticks(positions, _value_labels(xs))
        ax.set_xlabel(x)
        ax.set_ylabel(_label(ds, name))
        ax.grid(alpha=0.3)
    if hue:
        axes[0].legend(fontsize=7, title="x: not converged", title_fontsize=7)
    fig.suptitle((title + "\n" if title else "") + (held or ""), fontsize=9)
    return fig


def sweep_profiles_figure(ds, across: str, select=None, title: str = "") -> Figure:
    """Pressure, tangential stress and slip along Gamma_C for every value of the dimension ``across``."""
    if "profile_pressure" not in ds:
        raise ValueError(f"this sweep has no contact-boundary profiles ({ds.attrs.get('profiles', '')})")
    sub, held = _fixed(ds, (across,), select)
    x = ds["contact_x"].values
    surface = "contact_z" in ds.coords  # a 3D body: every vertex of the surface Gamma_C against its x
    fig = Figure(figsize=(13.0, 3.8), layout="constrained")
    axes = fig.subplots(1, 3)
    names = ("profile_pressure", "profile_tangential_stress", "profile_slip")
    for k, value in enumerate(sub[across].values):
        point = sub.sel({across: value})
        label = f"{across} = {_value_labels([value])[0]}" + ("" if int(point["status"]) == 0 else " (not converged)")
        style = dict(color=COLORS[k % len(COLORS)], label=label)
        style.update(dict(ls="none", marker=".", ms=3) if surface else dict(lw=1.3))
        for ax, name in zip(axes, names):
            values = point[name]
            if "contact_tangent" in values.dims:  # 3D: the magnitude of the tangential vector
                values = np.sqrt((values**2).sum("contact_tangent", skipna=False))
            ax.plot(x, values.values, **style)
    for ax, name in zip(axes, names):
        ax.set_xlabel("x on $\\Gamma_C$ [mm]")
        tangential = surface and "contact_tangent" in ds[name].dims
        ax.set_ylabel(("|" + _label(ds, name) + "|") if tangential else _label(ds, name))
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle((title + "\n" if title else "") + (held or ""), fontsize=9)
    return fig


def pareto_figure(ds, error: str = "error_h1", targets=(0.01,)) -> Figure:
    """Error against wall time and against DOFs for every converged run; the Pareto fronts drawn."""
    fig = Figure(figsize=(12.0, 4.6), layout="constrained")
    axes = fig.subplots(1, 2)
    ok = ds["status"].values == 0
    families = list(dict.fromkeys(str(f) for f in ds["family"].values))
    solvers = list(dict.fromkeys(str(s) for s in ds["solver"].values))
    fam = np.array([str(f) for f in ds["family"].values])
    sol = np.array([str(s) for s in ds["solver"].values])
    err = ds[error].values
    for ax, cost, front, xlabel in (
        (axes[0], "cost_time", "pareto_time", "wall time: assembly + solve [s]"),
        (axes[1], "n_dofs", "pareto_dofs", "free unknowns (DOFs)"),
    ):
        c = ds[cost].values.astype(float)
        for i, f in enumerate(families):
            for j, s in enumerate(solvers):
                sel = ok & (fam == f) & (sol == s)
                ax.scatter(
                    c[sel],
                    err[sel],
                    s=14,
                    color=COLORS[i % len(COLORS)],
                    marker=MARKERS[j % len(MARKERS)],
                    alpha=0.55,
                    linewidths=0,
                )
        on = ok & (ds[front].values == 1)
        order = np.argsort(c[on])
        ax.step(c[on][order], err[on][order], where="post", color="k", lw=1.2)
        ax.scatter(c[on], err[on], s=40, facecolors="none", edgecolors="k", linewidths=1.0)
        for t in targets:
            ax.axhline(t, color="grey", ls=":", lw=1)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(f"{error} (relative)")
        ax.grid(alpha=0.3, which="both")
    handles = [
        Line2D([], [], color=COLORS[i % len(COLORS)], marker="o", ls="", label=f) for i, f in enumerate(families)
    ]
    handles += [
        Line2D([], [], color="grey", marker=MARKERS[j % len(MARKERS)], ls="", label=s) for j, s in enumerate(solvers)
    ]
    handles += [Line2D([], [], color="k", marker="o", mfc="none", label="Pareto front")]
    axes[1].legend(handles=handles, fontsize=7, loc="upper right")
    fig.suptitle("speed-accuracy: every (family, solver, tolerance, stabilization, h)", fontsize=10)
    return fig


def stability_figure(ds) -> Figure:
    """Left: the outcome class of every case and solver (iterations written in); middle: worst check;
    right: the accuracy quantity's ratio cell / nodal_average (locking: away from 1)."""
    from vemkit.solvers.verification import STATUS_MEANINGS

    status = ds["status"].values.astype(int)
    cases = [str(c) for c in ds["case"].values]
    solvers = [str(s) for s in ds["solver"].values]
    height = max(4.0, 0.19 * len(cases) + 1.2)
    fig = Figure(figsize=(14.0, height), layout="constrained")
    left, right, locking = fig.subplots(1, 3, width_ratios=(1.0, 1.4, 0.8))
    palette = [
        "#4daf4a",
        "#e41a1c",
        "#ff7f00",
        "#984ea3",
        "#a65628",
        "#f781bf",
        "#999999",
        "#377eb8",
        "#ffff33",
        "#000000",
        "#66c2a5",
    ]
    cmap = ListedColormap(palette[: len(STATUS_MEANINGS)])
    norm = BoundaryNorm(np.arange(len(STATUS_MEANINGS) + 1) - 0.5, cmap.N)
    left.pcolormesh(np.arange(len(solvers) + 1) - 0.5, np.arange(len(cases) + 1) - 0.5, status, cmap=cmap, norm=norm)
    for i in range(len(cases)):
        for j in range(len(solvers)):
            its = int(ds["iterations"].values[i, j])
            if its >= 0:
                left.text(j, i, str(its), ha="center", va="center", fontsize=6)
    left.set_xticks(range(len(solvers)), solvers)
    left.set_yticks(range(len(cases)), cases, fontsize=6)
    left.invert_yaxis()
    used = sorted(set(status.ravel()))
    left.legend(
        handles=[Line2D([], [], color=palette[c], marker="s", ls="", ms=8, label=STATUS_MEANINGS[c]) for c in used],
        fontsize=6,
        loc="upper center",
        bbox_to_anchor=(0.5, -0.02 - 0.5 / height),
        ncol=1,
    )
    left.set_title("outcome (number: iterations)", fontsize=9)
    worst = ds["check_worst"].values.astype(float)
    for j, s in enumerate(solvers):
        values = np.where(np.isfinite(worst[:, j]), np.maximum(worst[:, j], 1e-17), np.nan)
        right.plot(values, np.arange(len(cases)), MARKERS[j], color=COLORS[j], label=s, ms=4)
    tol = float(ds.attrs.get("check_tol", 0.0) or 0.0)
    if tol > 0:
        right.axvline(tol, color="grey", ls=":", label=f"check tolerance {tol:g}")
    right.set_xscale("log")
    right.set_yticks(range(len(cases)), [""] * len(cases))
    right.set_ylim(len(cases) - 0.5, -0.5)
    right.set_xlabel("worst independent check (converged solves)")
    right.grid(alpha=0.3, which="both")
    right.legend(fontsize=7)
    _locking_panel(locking, ds)
    return fig


def _locking_panel(ax, ds) -> None:
    """The accuracy quantity where a case has a nodal_average twin: u_max(cell) / u_max(nodal_average)."""
    from vemkit.studies.robustness import nodal_average_ratio

    ratio = nodal_average_ratio(ds)
    rows = np.arange(len(ratio))
    cell = np.isfinite(ratio) & (ratio != 1.0)
    ax.plot(ratio[cell], rows[cell], "o", color=COLORS[1], ms=4, label="cell / nodal_average")
    ax.axvline(1.0, color="grey", ls=":")
    ax.set_yticks(range(len(ratio)), [""] * len(ratio))
    ax.set_ylim(len(ratio) - 0.5, -0.5)
    ax.set_xlabel("max |u|: volumetric_strain cell / nodal_average")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
