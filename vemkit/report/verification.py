"""The verification report: Markdown tables beside the published references, and one figure per scene.

- :func:`verification_markdown`: from a verification Dataset (``vemkit.studies.verification``), a
  table per scene: Cook's v(48, 52) against 23.96; Kirsch's exact errors with observed orders and
  the stress concentration against 3; Hertz's half-width and peak pressure against the formulas
  for the measured contact force; the L-bracket smoke runs. Undefined entries print as "–".
- :func:`scene_figure`: from one solution Dataset and its mesh, the mesh, the deformed shape (cells
  shaded by the von Mises stress) and a stress field; for a contact scene with a ``hertz``
  comparison also a zoom on the contact zone and the contact pressure against Hertz's ellipse.

Figures use matplotlib's object API (no pyplot state); save them with ``vemkit.report.figures.save``.
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.colors import TwoSlopeNorm
from matplotlib.figure import Figure

from vemkit.studies.verification import COOK_REFERENCE, KIRSCH_CONCENTRATION

#: per scene: (stress variable of the solution, label) drawn in the stress panel
STRESS_FIELDS = {
    "cook": ("von_mises", r"von Mises stress"),
    "kirsch": ("stress_11", r"$\sigma_{11}$"),
    "hertz": ("stress_22", r"$\sigma_{22}$"),
    "lbracket": ("von_mises", r"von Mises stress"),
}


# -- the tables -----------------------------------------------------------------------------------
def _fmt(value, spec: str = ".4g") -> str:
    value = float(value)
    return "–" if not math.isfinite(value) else format(value, spec)


def _pct(value) -> str:
    return _fmt(100.0 * float(value), "+.2f") + " %" if math.isfinite(float(value)) else "–"


def _rows(ds, scene: str, columns) -> list[str]:
    """Table rows of one scene: family, h, unknowns, then ``columns`` [(header, function of the run)]."""
    sub = ds.sel(scene=scene)
    head = "| family | h | unknowns | " + " | ".join(c[0] for c in columns) + " |"
    lines = [head, "|" + "---|" * (3 + len(columns))]
    for family in sub["family"].values:
        for level in sub["level"].values:
            run = sub.sel(family=family, level=level)
            if not math.isfinite(float(run["n_dofs"])):
                continue
            cells = [str(family), _fmt(run["h"]), _fmt(run["n_dofs"], ".0f")] + [f(run) for _, f in columns]
            lines.append("| " + " | ".join(cells) + " |")
    return lines


def _cook(ds) -> list[str]:
    lines = [
        "## Cook's membrane: v(48, 52) against the published 23.96",
        "",
        "Cook 1974; Belytschko, Liu, Moran & Elkhodary 2014, Table 8.1: the published value is the "
        "vertical displacement at the middle of the loaded edge; the top corner v(48, 60) still rises "
        "with refinement.",
        "",
    ]
    lines += _rows(
        ds,
        "cook",
        [
            ("v(48, 52)", lambda r: _fmt(r["v_mid"], ".5g")),
            ("vs 23.96", lambda r: _pct(r["v_mid_difference"])),
            ("v(48, 60)", lambda r: _fmt(r["v_corner"], ".5g")),
        ],
    )
    lines.append(f"| published | | | {COOK_REFERENCE} | | |")
    return lines


def _kirsch(ds) -> list[str]:
    lines = [
        "## Kirsch's plate: errors against the exact field, and the stress concentration",
        "",
        "Relative errors of Π₁u_h against the exact Kirsch displacement (imposed on the outer boundary); "
        "observed orders log(e_prev/e)/log(h_prev/h); σ11/S at the top of the hole (0, a), from the "
        f"stretch of the hole's boundary, against Kirsch's {KIRSCH_CONCENTRATION:g}.",
        "",
    ]
    lines += _rows(
        ds,
        "kirsch",
        [
            ("H1 error", lambda r: _fmt(r["error_h1"])),
            ("order", lambda r: _fmt(r["order_h1"], ".3f")),
            ("H1-semi error", lambda r: _fmt(r["error_h1_semi"])),
            ("order", lambda r: _fmt(r["order_h1_semi"], ".3f")),
            ("L2 error", lambda r: _fmt(r["error_l2"])),
            ("order", lambda r: _fmt(r["order_l2"], ".3f")),
            ("σ11/S at (0, a)", lambda r: _fmt(r["stress_concentration"], ".4f")),
        ],
    )
    lines.append(f"| Kirsch (expected orders) | | | 0 | 1 | 0 | 1 | 0 | 2 | {KIRSCH_CONCENTRATION:g} |")
    return lines


def _hertz(ds) -> list[str]:
    sub = ds.sel(scene="hertz")
    k = float(np.nanmax(sub["normal_k"].values))
    radius = float(np.nanmax(sub["radius"].values))
    lines = [
        "## Hertz: a half-disk pressed onto a stiff foundation",
        "",
        f"R = {radius:g}, k_ν = {k:g}; P the total contact force of the solution; Hertz: "
        "a = 2√(RP/(πE*)), p0 = 2P/(πa), E* = E (plane stress, rigid foundation).",
        "",
    ]
    lines += _rows(
        ds,
        "hertz",
        [
            ("P", lambda r: _fmt(r["contact_force"])),
            ("a", lambda r: _fmt(r["half_width"])),
            ("a Hertz", lambda r: _fmt(r["half_width_hertz"])),
            ("a vs Hertz", lambda r: _pct(r["half_width_difference"])),
            ("p0", lambda r: _fmt(r["peak_pressure"])),
            ("p0 Hertz", lambda r: _fmt(r["peak_pressure_hertz"])),
            ("p0 vs Hertz", lambda r: _pct(r["peak_pressure_difference"])),
        ],
    )
    return lines


def _bracket(ds) -> list[str]:
    lines = ["## L-bracket on a pad (smoke runs: solved and independently checked)", ""]
    lines += _rows(
        ds,
        "lbracket",
        [
            ("iterations", lambda r: _fmt(r["iterations"], ".0f")),
            ("contact force", lambda r: _fmt(r["contact_force"])),
            ("contact length", lambda r: _fmt(r["contact_length"])),
            ("max penetration", lambda r: _fmt(r["max_penetration"])),
            ("check", lambda r: _fmt(r["check_worst"], ".1e")),
        ],
    )
    return lines


SECTIONS = {"cook": _cook, "kirsch": _kirsch, "hertz": _hertz, "lbracket": _bracket}


def verification_markdown(ds) -> str:
    """The verification tables (the scenes of ``ds`` that have a section, in ``SECTIONS`` order)."""
    scenes = [str(s) for s in ds["scene"].values]
    parts = [
        "# Verification of the shipped scenes",
        "",
        f"Families: {', '.join(str(f) for f in ds['family'].values)}; commit {ds.attrs.get('git_commit', '?')}.",
        "",
    ]
    for name, section in SECTIONS.items():
        if name in scenes:
            parts += section(ds) + [""]
    return "\n".join(parts)


# -- the figures ----------------------------------------------------------------------------------
def von_mises(ds) -> np.ndarray:
    """Cell von Mises stress of plane stress: sqrt(s11² - s11 s22 + s22² + 3 s12²)."""
    s11, s22, s12 = (ds[k].values for k in ("stress_11", "stress_22", "stress_12"))
    return np.sqrt(s11**2 - s11 * s22 + s22**2 + 3.0 * s12**2)


def _cells(mesh, xy=None) -> list:
    xy = mesh.vertices if xy is None else xy
    off = mesh.cell_offsets
    return [xy[mesh.cell_vertices[off[k] : off[k + 1]]] for k in range(mesh.n_cells)]


def _field_panel(fig, ax, mesh, values, label, xy=None, cmap=None, edges=False):
    """Cell values on the (possibly deformed) cells; a field of both signs on a diverging map centred at 0."""
    norm = None
    if cmap is None:
        lo, hi = float(np.min(values)), float(np.max(values))
        cmap, norm = ("RdBu_r", TwoSlopeNorm(0.0, lo, hi)) if lo < 0.0 < hi else ("viridis", None)
    art = PolyCollection(
        _cells(mesh, xy),
        array=values,
        cmap=cmap,
        norm=norm,
        edgecolors="k" if edges else "face",
        linewidths=0.15 if edges else 0.0,
    )
    ax.add_collection(art)
    ax.autoscale_view()
    ax.set_aspect("equal")
    fig.colorbar(art, ax=ax, shrink=0.8, label=label)


def _magnification(mesh, u) -> float:
    extent = float(np.ptp(mesh.vertices, axis=0).max())
    umax = float(np.abs(u).max()) or 1.0
    raw = 0.1 * extent / umax
    return float(10.0 ** math.floor(math.log10(raw))) * (5 if raw / 10.0 ** math.floor(math.log10(raw)) >= 5 else 1)


def scene_figure(name: str, mesh, ds, title: str = "", hertz=None) -> Figure:
    """Mesh, deformed shape and a stress field of one solution; for ``hertz`` also zooms on the
    contact and the pressure against Hertz's ellipse (``hertz`` = (a, p0) of the comparison)."""
    field, label = STRESS_FIELDS.get(name, ("von_mises", "von Mises stress"))
    values = von_mises(ds) if field == "von_mises" else ds[field].values
    u = np.stack([ds["u1"].values, ds["u2"].values], axis=1)
    contact = "contact_x" in ds and name == "hertz"
    fig = Figure(figsize=(16.0 if contact else 15.0, 8.5 if contact else 4.6), layout="constrained")
    axes = fig.subplots(2, 3).ravel() if contact else fig.subplots(1, 3)
    ax = axes[0]
    ax.add_collection(LineCollection(mesh.vertices[mesh.edges], colors="k", linewidths=0.3))
    for side, edges in mesh.boundary.items():
        ax.add_collection(
            LineCollection(
                mesh.vertices[edges], linewidths=1.6, label=side, colors=f"C{list(mesh.boundary).index(side) % 10}"
            )
        )
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.legend(fontsize=7, loc="best")
    ax.set_title(f"mesh: {mesh.n_cells} cells, sides coloured", fontsize=9)
    m = _magnification(mesh, u)
    deformed = mesh.vertices + m * u
    _field_panel(fig, axes[1], mesh, von_mises(ds), "von Mises stress", xy=deformed, cmap="Greys")
    axes[1].add_collection(
        LineCollection(mesh.vertices[mesh.boundary_edges], colors="C3", linewidths=0.6, linestyles=":")
    )
    axes[1].set_title(f"deformed shape ×{m:g} (dotted: undeformed)", fontsize=9)
    _field_panel(fig, axes[2], mesh, values, label)
    axes[2].set_title(label, fontsize=9)
    if contact:
        _contact_panels(fig, axes[3:], mesh, ds, values, label, hertz)
    for ax in axes[:3]:
        ax.set_xlabel("x")
        ax.set_ylabel("y")
    fig.suptitle(title or f"{name}: {ds.attrs.get('mesh_family', '')} mesh, {ds.attrs.get('n_dofs', '?')} unknowns")
    return fig


def _contact_panels(fig, axes, mesh, ds, values, label, hertz):
    """A zoom on the contact zone (stress, mesh drawn), the remaining gap g - u_nu and the pressure
    along the contact side against Hertz's p0 √(1 - x²/a²) for the measured force (``hertz`` = (a, p0))."""
    x, p = ds["contact_x"].values, ds["normal_pressure"].values
    touching = x[p > 0]
    a = hertz[0] if hertz else (0.5 * float(np.ptp(touching)) if touching.size else 0.1)
    centre = float(np.mean(touching)) if touching.size else float(np.mean(x))
    y0 = float(ds["contact_y"].values.min())
    ax = axes[0]
    _field_panel(fig, ax, mesh, values, label, edges=True)
    ax.set_xlim(centre - 3 * a, centre + 3 * a)
    ax.set_ylim(y0 - 0.5 * a, y0 + 3 * a)
    ax.set_title(f"{label} near the contact, mesh drawn", fontsize=9)
    for ax, values_x, what, unit in (
        (axes[1], -ds["penetration"].values, "remaining gap $g - u_\\nu$ (0: in contact)", "gap"),
        (axes[2], p, "contact pressure $p_\\nu$ along the contact side", "pressure"),
    ):
        ax.plot(x, values_x, "o-", ms=2.5, lw=0.8, label="vemkit (nodal)")
        if hertz:
            ax.axvline(centre - hertz[0], color="k", ls=":", lw=1)
            ax.axvline(centre + hertz[0], color="k", ls=":", lw=1, label="Hertz: $x = \\pm a$")
        ax.set_xlim(centre - 2 * a, centre + 2 * a)
        ax.set_xlabel("x")
        ax.set_ylabel(unit)
        ax.set_title(what, fontsize=9)
    if hertz:
        t = np.linspace(-1.0, 1.0, 401)
        axes[2].plot(
            centre + hertz[0] * t,
            hertz[1] * np.sqrt(1.0 - t**2),
            "k--",
            lw=1.2,
            label=f"Hertz: a = {hertz[0]:.4g}, $p_0$ = {hertz[1]:.4g}",
        )
    axes[1].set_ylim(-0.05 * a * a, 1.5 * a * a)
    for ax in axes[1:]:
        ax.legend(fontsize=7, loc="upper right")
