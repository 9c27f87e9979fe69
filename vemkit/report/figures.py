"""Figures of the paper and beyond, drawn with matplotlib's object API (no pyplot state; importing it selects no backend).

- :func:`displacement_figure`: u1 and u2 on a polygonal mesh (Figs. 3-5): the vertex values
  interpolated linearly on an ear-clipping triangulation of the cells (Gouraud shading), the
  mesh edges drawn over them;
- :func:`deformed_figure`: 2D, the deformed mesh, displacements magnified, every cell filled in grey
  by its shear energy density |dev sigma|^2/(4 mu) (Fig. 6), the foundation's surface and the
  penetrated part of Gamma_C marked; 3D, the deformed boundary faces coloured by the von Mises
  stress of their cells and, with contact, Gamma_C's zones and slip (:func:`contact_figure`);
- :func:`contact_figure`: 2D, along Gamma_C, the normal pressure, the tangential stress with the
  friction bound, the slip and the penetration, over the separated/stick/slip zones; 3D, Gamma_C
  seen from below: the separated/stick/slip state at every contact vertex and the slip as arrows;
- :func:`convergence_figure`: log-log errors against h for every family and stabilization, with
  the paper's Table 1 and a slope-1 guide.

Every function returns a ``matplotlib.figure.Figure``; :func:`save` writes it as PNG and PDF.
They read solution Datasets of either dimension as written by ``vemkit solve`` (docs/reference/files.md:
the mesh says which, or the Dataset's topology variable) and convergence Datasets
(``vemkit.studies.convergence``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.tri import Triangulation
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

from vemkit.mesh.ugrid import topology_dimension

STATE_COLORS = {0: ("separated", "#d9d9d9"), 1: ("stick", "#9ecae1"), 2: ("slip", "#fdae6b")}
FAMILY_COLORS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#7f7f7f")
STAB_STYLES = (("o", "-"), ("s", "--"), ("^", ":"), ("D", "-."))


def save(fig: Figure, *paths, dpi: int = 150) -> list[Path]:
    """Write ``fig`` to every path (format from the suffix: .png, .pdf, ...)."""
    out = []
    for p in paths:
        p = Path(p)
        p.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(p, dpi=dpi, bbox_inches="tight")
        out.append(p)
    return out


def _cell_polygons(mesh, vertices=None) -> list[np.ndarray]:
    xy = mesh.vertices if vertices is None else vertices
    off = mesh.cell_offsets
    return [xy[mesh.cell_vertices[off[k] : off[k + 1]]] for k in range(mesh.n_cells)]


def _edges(mesh, vertices=None, **kw) -> LineCollection:
    xy = mesh.vertices if vertices is None else vertices
    return LineCollection(xy[mesh.edges], **kw)


def _scene(ds) -> dict:
    return yaml.safe_load(ds.attrs.get("scene", "")) or {}


# -- Figs. 3-5 ------------------------------------------------------------------------------------
def displacement_figure(mesh, u1, u2, title: str = "", cmap: str = "jet", edges: bool = True) -> Figure:
    """Two panels, u1 and u2 (per vertex) on the mesh, each with its colour bar."""
    from vemkit.mesh.triangulate import triangulate_cells

    tri, _ = triangulate_cells(mesh)
    triangulation = Triangulation(mesh.vertices[:, 0], mesh.vertices[:, 1], tri)
    fig = Figure(figsize=(10.0, 4.4), layout="constrained")
    axes = fig.subplots(1, 2)
    width = 0.25 if mesh.n_cells <= 4096 else 0.1
    for ax, values, name in zip(axes, (u1, u2), ("$u_1$", "$u_2$")):
        values = np.asarray(values, dtype=float)
        art = ax.tripcolor(triangulation, values, shading="gouraud", cmap=cmap, rasterized=True)
        if edges:
            ax.add_collection(_edges(mesh, colors="k", linewidths=width, alpha=0.45))
        ax.set_aspect("equal")
        ax.set_xlim(0, 1)
        ax.set_ylim(0, 1)
        ax.set_xlabel("$x_1$ (mm)")
        ax.set_ylabel("$x_2$ (mm)")
        ax.set_title(f"{name} (mm): min {values.min():.4g}, max {values.max():.4g}", fontsize=10)
        fig.colorbar(art, ax=ax, shrink=0.9)
    if title:
        fig.suptitle(title)
    return fig


# -- Fig. 6 ---------------------------------------------------------------------------------------
def auto_magnification(u: np.ndarray, fraction: float = 0.15) -> float:
    """A round factor that makes the largest displacement about ``fraction`` of the unit domain."""
    umax = float(np.max(np.abs(u))) if np.size(u) else 0.0
    if umax <= 0:
        return 1.0
    raw = fraction / umax
    if raw >= 1.0:
        return float(max(1, round(raw)))
    return float(10.0 ** np.floor(np.log10(raw)) * round(raw / 10.0 ** np.floor(np.log10(raw))))


def deformed_figure(mesh, ds, magnification: float | None = None, title: str = "", cmap: str | None = None) -> Figure:
    """The deformed body x + M u: a 2D mesh (:func:`_deformed_plane`) or a 3D body (:func:`_deformed_body`),
    ``DEFORMED_FIGURES``."""
    draw, default_cmap = DEFORMED_FIGURES[mesh.dimension]
    return draw(mesh, ds, magnification, title, cmap or default_cmap)


def _deformed_plane(mesh, ds, magnification: float | None, title: str, cmap: str) -> Figure:
    """The deformed mesh x + M u, grey = shear energy density per cell, Gamma_C penetration in red.

    The foundation's surface lies at distance g_a below Gamma_C: drawn at y = -M g_a, so that a
    point of Gamma_C lies below the line exactly where it penetrates (u_nu > g_a, docs/reference/mathematics.md).
    """
    u = np.stack([ds["u1"].values, ds["u2"].values], axis=1)
    m = auto_magnification(u) if magnification is None else float(magnification)
    xy = mesh.vertices + m * u
    energy = np.asarray(ds["shear_energy_density"].values, dtype=float)
    fig = Figure(figsize=(7.5, 6.2), layout="constrained")
    ax = fig.subplots()
    polys = PolyCollection(_cell_polygons(mesh, xy), array=energy, cmap=cmap, edgecolors="k", linewidths=0.4)
    ax.add_collection(polys)
    cb = fig.colorbar(polys, ax=ax, shrink=0.85)
    cb.set_label(r"shear energy density $|\mathrm{dev}\,\sigma|^2/(4\mu)$ (daN/mm$^2$)")
    # the undeformed outline
    ax.plot([0, 1, 1, 0, 0], [0, 0, 1, 1, 0], color="0.55", lw=0.8, ls=":", label="undeformed body")
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    pad = 0.06 * max(hi - lo)
    scene = _scene(ds)
    gap = scene.get("contact", {}).get("gap")
    if "contact_x" in ds and gap is not None:
        try:
            g = float(gap)
        except (TypeError, ValueError):
            g = None  # a gap expression: drawn from the per-vertex penetration only
        x0, x1 = min(lo[0], 0.0) - pad, max(hi[0], 1.0) + pad
        if g is not None:
            yf = -m * g
            ax.fill_between([x0, x1], yf, min(lo[1], yf) - pad, color="#c6a27a", alpha=0.35, lw=0)
            ax.plot([x0, x1], [yf, yf], color="#8c510a", lw=1.2, label=f"foundation surface ($g_a$ = {g:g} mm, ×{m:g})")
            lo[1] = min(lo[1], yf)
        verts = ds["contact_vertex"].values.astype(int)
        pen = ds["penetration"].values > 0
        p = xy[verts]
        segs = [p[i : i + 2] for i in range(len(p) - 1) if pen[i] and pen[i + 1]]
        if segs:
            ax.add_collection(LineCollection(segs, colors="red", linewidths=2.5, zorder=5))
        if pen.any():
            ax.plot(
                p[pen, 0], p[pen, 1], "o", color="red", ms=3, zorder=6, label=r"penetration $u_\nu > g_a$ on $\Gamma_C$"
            )
        ax.set_xlim(x0, x1)
    else:
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("$x_1 + M u_1$ (mm)")
    ax.set_ylabel("$x_2 + M u_2$ (mm)")
    ax.legend(loc="upper right", fontsize=8, framealpha=0.9)
    ax.set_title(title or f"deformed mesh, displacements magnified ×{m:g}", fontsize=10)
    return fig


def body_magnification(vertices, u, fraction: float = 0.1) -> float:
    """A factor 1 or 5 times a power of ten that makes the largest displacement about ``fraction``
    of the body's size (3D)."""
    size = float(np.ptp(vertices, axis=0).max())
    top = float(np.abs(u).max())
    if top == 0.0:
        return 1.0
    raw = fraction * size / top
    return float(10 ** np.floor(np.log10(raw)) * (5 if raw / 10 ** np.floor(np.log10(raw)) >= 5 else 1))


def _deformed_body(mesh, ds, magnification: float | None, title: str, cmap: str) -> Figure:
    """The deformed boundary of a 3D body coloured by von Mises; Gamma_C's states and slip from below."""
    u = np.stack([ds["u1"].values, ds["u2"].values, ds["u3"].values], axis=1)
    m = body_magnification(mesh.vertices, u) if magnification is None else float(magnification)
    xyz = mesh.vertices + m * u
    faces = mesh.boundary_faces
    owner = mesh.face_cells[faces].max(axis=1)  # the one cell of a boundary face
    contact = "contact_state" in ds
    fig = Figure(figsize=(11.0 if contact else 6.5, 5.0), layout="constrained")
    ax = fig.add_subplot(1, 2 if contact else 1, 1, projection="3d")
    surface = Poly3DCollection([xyz[mesh.face(f)] for f in faces], cmap=cmap, edgecolors="k", linewidths=0.25)
    surface.set_array(np.asarray(ds["von_mises"].values, dtype=float)[owner])
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
        _contact_zones(fig.add_subplot(1, 2, 2), ds)
    return fig


#: dimension -> (the figure of the deformed body, its default colour map)
DEFORMED_FIGURES = {2: (_deformed_plane, "Greys"), 3: (_deformed_body, "viridis")}


# -- the contact boundary -----------------------------------------------------------------------
def _state_spans(ax, x, state):
    """Shade the separated/stick/slip zones: each vertex owns the half edges around it."""
    mid = np.concatenate([[x[0]], 0.5 * (x[1:] + x[:-1]), [x[-1]]])
    for i, s in enumerate(state):
        ax.axvspan(mid[i], mid[i + 1], color=STATE_COLORS[int(s)][1], alpha=0.55, lw=0)


def contact_figure(ds, title: str = "") -> Figure:
    """Gamma_C of a solution of either dimension: its profiles along the line (2D,
    :func:`_contact_profiles`) or its zones and slip seen from below (3D, :func:`_contact_zones`)."""
    if topology_dimension(ds) == 3:
        fig = Figure(figsize=(6.0, 5.0), layout="constrained")
        _contact_zones(fig.add_subplot(), ds)
        if title:
            fig.suptitle(title, fontsize=11)
        return fig
    return _contact_profiles(ds, title)


def _contact_profiles(ds, title: str) -> Figure:
    """Along Gamma_C, over the separated/stick/slip zones: the normal pressure; the tangential
    stress with the friction bound ±p_tau; the slip and the penetration; the zones."""
    from vemkit.contact.laws import power_law

    x = ds["contact_x"].values
    order = np.argsort(x)
    x = x[order]
    get = {
        k: ds[k].values[order] for k in ("normal_pressure", "tangential_stress", "slip", "penetration", "contact_state")
    }
    friction = _scene(ds).get("contact", {}).get("friction")
    fig = Figure(figsize=(8.0, 9.0), layout="constrained")
    axes = fig.subplots(4, 1, sharex=True, height_ratios=(3, 3, 3, 1))
    for ax in axes:
        _state_spans(ax, x, get["contact_state"])
        ax.axhline(0, color="k", lw=0.5)
    ax = axes[0]
    ax.plot(x, get["normal_pressure"], "-o", ms=2.5, color="#08519c", label=r"normal pressure $p_\nu(u_\nu - g_a)$")
    ax.set_ylabel("daN/mm$^2$")
    ax.legend(fontsize=8, loc="best", framealpha=0.9)
    ax = axes[1]
    ax.plot(x, get["tangential_stress"], "-s", ms=2.5, color="#a50f15", label=r"tangential stress $\sigma_\tau$")
    bound = ds["friction_bound"].values[order] if "friction_bound" in ds else None
    if bound is None and friction is not None:
        bound = power_law(get["penetration"], float(friction["k"]), float(friction["m"]))
    if bound is not None:
        ax.plot(x, bound, "--", color="0.3", lw=1, label=r"friction bound $\pm p_\tau(u_\nu - g_a)$")
        ax.plot(x, -bound, "--", color="0.3", lw=1)
    ax.set_ylabel("daN/mm$^2$")
    ax.legend(fontsize=8, loc="best", framealpha=0.9)
    ax = axes[2]
    ax.plot(x, get["slip"], "-o", ms=2.5, color="#54278f", label=r"slip $u_\tau$")
    ax.plot(x, get["penetration"], "-^", ms=2.5, color="#006d2c", label=r"penetration $u_\nu - g_a$")
    ax.set_ylabel("mm")
    ax.legend(fontsize=8, loc="best", framealpha=0.9)
    ax = axes[3]
    ax.set_yticks([])
    ax.set_ylabel("zone")
    counts = {code: int(np.sum(get["contact_state"] == code)) for code in STATE_COLORS}
    ax.legend(
        handles=[Patch(color=c, label=f"{name} ({counts[code]})") for code, (name, c) in STATE_COLORS.items()],
        ncol=3,
        fontsize=8,
        loc="center",
        framealpha=0.9,
    )
    ax.set_xlabel(r"$x_1$ on $\Gamma_C$ (mm)")
    ax.set_xlim(x[0], x[-1])
    fig.suptitle(title or r"contact boundary $\Gamma_C$", fontsize=11)
    return fig


def _contact_zones(ax, ds) -> None:
    """3D: Gamma_C projected on its mean plane's two coordinate axes: states and slip arrows."""
    xyz = np.stack([ds["contact_x"].values, ds["contact_y"].values, ds["contact_z"].values], axis=1)
    normal = np.array([ds[f"contact_normal_{a}"].values.mean() for a in "xyz"])
    keep = [i for i in range(3) if i != int(np.argmax(np.abs(normal)))]
    names = np.array(["x", "y", "z"])[keep]
    slip = ds["slip"].values  # (n, 2) in the per-vertex basis
    t1 = np.stack([ds[f"contact_tangent1_{a}"].values for a in "xyz"], axis=1)
    t2 = np.stack([ds[f"contact_tangent2_{a}"].values for a in "xyz"], axis=1)
    p, s = xyz[:, keep], (slip[:, :1] * t1 + slip[:, 1:2] * t2)[:, keep]
    colors = [STATE_COLORS[k][1] for k in ds["contact_state"].values.astype(int)]
    ax.scatter(p[:, 0], p[:, 1], c=colors, s=30, edgecolors="0.3", linewidths=0.4).set_zorder(2)
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


# -- convergence ----------------------------------------------------------------------------------
def convergence_figure(ds, norm: str = "h1", paper: bool = True, title: str = "") -> Figure:
    """Errors against h on log-log axes: colour = family, marker/line = stabilization; slope-1 guide.

    ``norm``: "paper" (the paper's measure, error_paper, with the paper's Table 1 marked), "h1" or
    "h1_semi" (Pi_1 on each mesh).
    """
    from vemkit.exceptions import ResultError
    from vemkit.studies.paper import PAPER_TABLE1

    keys = {"paper": "error_paper", "h1": "error_h1", "h1_semi": "error_h1_semi"}
    if norm not in keys:
        raise ResultError(f"convergence figure norm {norm!r}: use one of {', '.join(keys)}")
    key = keys[norm]
    if key not in ds:
        raise ResultError(f"the convergence file has no {key} (norm {norm!r}): recompute it with this vemkit")
    fig = Figure(figsize=(7.5, 5.5), layout="constrained")
    ax = fig.subplots()
    h = ds["h"].values
    values = []
    for i, fam in enumerate(ds["family"].values):
        for j, stab in enumerate(ds["stabilization"].values):
            e = ds[key].sel(family=fam, stabilization=stab).values.astype(float)
            ok = np.isfinite(e) & (e > 0) & (e != -9999.0)
            if not ok.any():
                continue
            marker, line = STAB_STYLES[j % len(STAB_STYLES)]
            ax.loglog(
                h[ok],
                e[ok],
                marker=marker,
                ls=line,
                color=FAMILY_COLORS[i % len(FAMILY_COLORS)],
                ms=4.5,
                lw=1.2,
                label=f"{fam} / {stab}",
            )
            values.append(e[ok])
    if paper and norm == PAPER_TABLE1["norm"]:
        ax.loglog(PAPER_TABLE1["h"], PAPER_TABLE1["error"], "kx", ms=8, mew=2, label="paper, Table 1")
    if values:
        allv = np.concatenate(values)
        hh = np.array([h.min(), h.max()])
        c = 0.5 * np.exp(np.mean(np.log(allv))) / np.exp(np.mean(np.log(h)))
        ax.loglog(hh, c * hh, "k--", lw=1.5, label="slope 1")
    ax.set_xlabel("$h = 1/n$ (mm)")
    ax.set_ylabel(
        {
            "paper": r"$|\Pi_1^{ref}(I_{ref} u_h - u_{ref})|_{H^1} / |\Pi_1^{ref} u_{ref}|_{H^1}$",
            "h1": r"$\|\Pi_1(u_h - u_{ref})\|_{H^1} / \|\Pi_1 u_{ref}\|_{H^1}$",
            "h1_semi": r"$|\Pi_1(u_h - u_{ref})|_{H^1} / |\Pi_1 u_{ref}|_{H^1}$",
        }[norm]
    )
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2, loc="lower right", framealpha=0.9)
    ax.set_title(title or "convergence against the square $h = 2^{-8}$ reference", fontsize=10)
    return fig
