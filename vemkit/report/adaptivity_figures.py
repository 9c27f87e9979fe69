"""Figures of the adaptive runs (docs/reference/files.md), matplotlib's object API.

- :func:`adaptive_convergence_figure`: true error and estimate against DOFs, adaptive and uniform
  refinement on one log-log plot, with the fitted rates (``vemkit.studies.adaptivity_compare``) and
  an N^(-1/d) guide (the optimal rate of k = 1 elements in d dimensions);
- :func:`mesh_sequence_figure`: meshes of an adaptive run, every cell coloured by its indicator η_K
  and, below, by its diameter (the grading); a 3D mesh is drawn as its cut by a plane
  (``vemkit.report.mesh_cuts``).

Each returns a ``matplotlib.figure.Figure``; save with ``vemkit.report.figures.save``.
"""

from __future__ import annotations

import numpy as np
from matplotlib.collections import PolyCollection
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure

from vemkit.report.mesh_cuts import drawn_cells
from vemkit.studies.adaptivity_compare import fitted_rate

STYLES = {"adaptive": ("#d62728", "o"), "uniform": ("#1f77b4", "s")}


def adaptive_convergence_figure(
    histories: dict, error: str = "true_error_h1", title: str = "", dimension: int = 2
) -> Figure:
    """``histories``: {"adaptive": history, "uniform": history} (``adaptivity_compare.history``);
    ``dimension``: the body's, for the guide N^(-1/d)."""
    fig = Figure(figsize=(6.6, 4.8), layout="constrained")
    ax = fig.subplots()
    for name, h in histories.items():
        color, marker = STYLES.get(name, ("k", "^"))
        dofs = h["n_dofs"]
        if error in h and error != "estimate":  # the estimate has its own line below
            rate = fitted_rate(dofs, h[error])
            ax.loglog(
                dofs,
                h[error],
                marker=marker,
                color=color,
                ms=4,
                lw=1.2,
                label=f"{name}: {error.replace('_', ' ')} (rate {rate['rate']:.2f})",
            )
            fit = np.array([rate["from_dofs"], rate["to_dofs"]], float)
            ax.loglog(fit, rate["constant"] * fit ** rate["rate"], color=color, lw=3, alpha=0.25)
        est = fitted_rate(dofs, h["estimate"])
        ax.loglog(
            dofs,
            h["estimate"],
            marker=marker,
            mfc="none",
            color=color,
            ms=4,
            lw=1,
            ls="--",
            label=f"{name}: estimate η (rate {est['rate']:.2f})",
        )
    everything = np.concatenate([h["n_dofs"] for h in histories.values()])
    first = histories.get("adaptive", next(iter(histories.values())))
    start = first.get(error, first["estimate"])[0]
    guide = np.array([everything.min(), everything.max()], float)
    ax.loglog(
        guide, 0.6 * start * (guide / guide[0]) ** (-1.0 / dimension), color="grey", ls=":", lw=1,
        label=f"N$^{{-1/{dimension}}}$",
    )  # fmt: skip
    ax.set_xlabel("free unknowns N (DOFs)")
    ax.set_ylabel("relative error / estimate")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    if title:
        ax.set_title(title, fontsize=10)
    return fig


def _cells_panel(fig, ax, drawn, values, label: str, cmap: str):
    polygons, cells = drawn
    values = np.maximum(np.asarray(values, float)[cells], np.finfo(float).tiny)
    positive = values[values > np.finfo(float).tiny]
    norm = LogNorm(vmin=positive.min() if positive.size else 1e-300, vmax=values.max(initial=1e-300))
    collection = PolyCollection(
        polygons,
        array=values,
        cmap=cmap,
        norm=norm,
        edgecolors="k",
        linewidths=0.15 if len(polygons) < 5000 else 0.0,
        rasterized=True,
    )
    ax.add_collection(collection)
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
    fig.colorbar(collection, ax=ax, shrink=0.8, label=label)


def mesh_sequence_figure(panels, title: str = "", cut=None) -> Figure:
    """``panels``: [(mesh, indicator per cell, label), ...]; one column each: η_K (top) and the cell
    diameter h_K (bottom: the grading of the mesh), both on log colour scales. A 3D mesh is drawn as
    its section by the plane ``cut`` ({axis, at}; ``vemkit.report.mesh_cuts``)."""
    count = len(panels)
    fig = Figure(figsize=(3.4 * count, 6.4), layout="constrained")
    axes = np.asarray(fig.subplots(2, count)).reshape(2, count)
    for column, (mesh, indicator, label) in enumerate(panels):
        drawn = drawn_cells(mesh, cut)
        _cells_panel(fig, axes[0, column], drawn, indicator, "η$_K$", "viridis")
        _cells_panel(fig, axes[1, column], drawn, mesh.cell_diameters, "cell diameter h$_K$", "magma")
        axes[0, column].set_title(f"{label}, {mesh.n_cells} cells", fontsize=9)
    if title:
        fig.suptitle(title, fontsize=10)
    return fig
