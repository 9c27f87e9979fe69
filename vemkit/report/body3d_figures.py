"""The picture of one 3D solution (a ``mesh3d`` solution file read by :func:`vemkit.read_solution`),
matplotlib's object API:

- :func:`body3d_figure`: the deformed body (its boundary faces, displacements magnified, coloured by
  the von Mises stress of the cell each face belongs to) and, when the scene has contact, the
  contact boundary Γ_C seen from below: the state separated / stick / slip at every contact vertex
  and the slip u_τ as arrows.
"""

from __future__ import annotations

import numpy as np
from matplotlib.collections import PathCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

from vemkit.report.figures import STATE_COLORS


def _magnification(vertices, u, fraction: float = 0.1) -> float:
    """A round factor that makes the largest displacement about ``fraction`` of the body's size."""
    size = float(np.ptp(vertices, axis=0).max())
    top = float(np.abs(u).max())
    if top == 0.0:
        return 1.0
    raw = fraction * size / top
    return float(10 ** np.floor(np.log10(raw)) * (5 if raw / 10 ** np.floor(np.log10(raw)) >= 5 else 1))


def body3d_figure(mesh, ds, magnification: float | None = None, title: str = "", cmap: str = "viridis") -> Figure:
    """The deformed boundary of a 3D body coloured by von Mises; Γ_C's states and slip from below."""
    u = np.stack([ds["u1"].values, ds["u2"].values, ds["u3"].values], axis=1)
    m = _magnification(mesh.vertices, u) if magnification is None else float(magnification)
    xyz = mesh.vertices + m * u
    faces = mesh.boundary_faces
    owner = mesh.face_cells[faces].max(axis=1)  # the one cell of a boundary face
    vm = np.asarray(ds["von_mises"].values, dtype=float)[owner]
    contact = "contact_state" in ds
    fig = Figure(figsize=(11.0 if contact else 6.5, 5.0), layout="constrained")
    ax = fig.add_subplot(1, 2 if contact else 1, 1, projection="3d")
    polygons = [xyz[mesh.face(f)] for f in faces]
    surface = Poly3DCollection(polygons, cmap=cmap, edgecolors="k", linewidths=0.25)
    surface.set_array(vm)
    ax.add_collection3d(surface)
    lo, hi = xyz.min(axis=0), xyz.max(axis=0)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(tuple(np.maximum(hi - lo, 1e-12)))
    ax.view_init(elev=22, azim=-58)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("z")
    ax.set_title(title or f"deformed body, displacements ×{m:g}", fontsize=10)
    fig.colorbar(surface, ax=ax, shrink=0.7, label="von Mises stress of the cell")
    if contact:
        _contact_panel(fig.add_subplot(1, 2, 2), ds)
    return fig


def _contact_panel(ax, ds) -> None:
    """Γ_C projected on its mean plane's two coordinate axes: states and slip arrows."""
    xyz = np.stack([ds["contact_x"].values, ds["contact_y"].values, ds["contact_z"].values], axis=1)
    normal = np.array([ds[f"contact_normal_{a}"].values.mean() for a in "xyz"])
    keep = [i for i in range(3) if i != int(np.argmax(np.abs(normal)))]
    names = np.array(["x", "y", "z"])[keep]
    state = ds["contact_state"].values.astype(int)
    slip = ds["slip"].values  # (n, 2) in the per-vertex basis
    t1 = np.stack([ds[f"contact_tangent1_{a}"].values for a in "xyz"], axis=1)
    t2 = np.stack([ds[f"contact_tangent2_{a}"].values for a in "xyz"], axis=1)
    slip_xyz = slip[:, :1] * t1 + slip[:, 1:2] * t2
    p, s = xyz[:, keep], slip_xyz[:, keep]
    colors = [STATE_COLORS[k][1] for k in state]
    points: PathCollection = ax.scatter(p[:, 0], p[:, 1], c=colors, s=30, edgecolors="0.3", linewidths=0.4)
    points.set_zorder(2)
    moving = np.linalg.norm(s, axis=1) > 0
    if moving.any():
        ax.quiver(p[moving, 0], p[moving, 1], s[moving, 0], s[moving, 1], color="k", width=0.003, zorder=3)
    handles = [
        Line2D([], [], marker="o", ls="", color=STATE_COLORS[k][1], markeredgecolor="0.3", label=STATE_COLORS[k][0])
        for k in sorted(STATE_COLORS)
    ]
    handles.append(Line2D([], [], color="k", label=r"slip $u_\tau$ (direction, relative length)"))
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=4, fontsize=8)
    ax.set_aspect("equal")
    ax.set_xlabel(names[0])
    ax.set_ylabel(names[1])
    ax.set_title(r"the contact boundary $\Gamma_C$: states and slip", fontsize=10)
