"""Verification of the shipped scenes against published and closed-form references (issue 11).

Each case solves one scene of ``config/scenes`` on every mesh family at several mesh sizes
(``discretization.mesh: {family, h}``, coarse to fine) and measures what the literature gives:

- ``cook`` (Cook's membrane): the vertical displacement at the middle of the loaded edge (48, 52)
  against the published 23.96 (Cook 1974; Belytschko et al. 2014, Table 8.1). The published value
  is the mid-edge one: the top corner (48, 60), also recorded, still rises with refinement (25.1
  at 46 000 unknowns). A point of an edge is evaluated on that edge: u_h is linear along edges.
- ``kirsch`` (plate with a hole under remote tension S): the relative errors of Π_1 u_h against the
  exact field (``error_h1``, ``error_h1_semi``, ``error_l2`` of the solution, docs/reference/files.md) with their
  observed orders, and the stress concentration σ11(0, a)/S against 3 (Kirsch 1898). On the
  traction-free hole σ11 = σ_tt = E ε_tt (plane stress), ε_tt the stretch of the hole's chord
  within ``STRESS_WINDOW`` h of the top (:func:`free_boundary_stress`): the cell stresses are
  constant per cell and O(h) off at a boundary point where σ11 falls by 7 S per unit radius.
- ``hertz`` (a half-disk pressed onto a stiff compliant foundation): from the contact solution,
  the total contact force P = Σ_c w_c p_c (-ν_c · e2) (doubled when the scene models half of the
  contact, ``symmetry_x``), the half-width a of the zone where u_ν - g > 0
  (:func:`contact_half_width`) and the peak nodal pressure p0; against Hertz (H. Hertz, J. reine
  angew. Math. 92, 1882; the cylinder formulas as in K. L. Johnson, "Contact Mechanics", 1985)
  a_H = 2 √(R P / (π E*)), p0_H = 2 P / (π a_H), E* = E in plane stress (the paper's C) on a rigid
  foundation, R the radius of the contact side's arc.
- ``lbracket``: a smoke run (solved, verified; contact force, contact length, peak penetration).

:func:`run_case` returns one record (a dict) per mesh size; :func:`verification_dataset` gathers
records on the grid scene x family x level (level 0 the coarsest), NaN where a quantity does not
apply; :func:`write_verification` stores it with declared fill values (``vemkit.io.fill_values``).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from vemkit.exceptions import InputError, ResultError
from vemkit.io.fill_values import read_with_fill_values, write_with_fill_values
from vemkit.io.provenance import git_commit, package_versions
from vemkit.studies.convergence import convergence_orders

#: options of each family in the verification (hanging: refined once at the case's ``refine_side``)
FAMILY_OPTIONS = {"square": {}, "triangle": {"seed": 1}, "voronoi": {"seed": 1}, "hanging": {"levels": 1}}
COOK_REFERENCE = 23.96  # v at (48, 52): Cook 1974; Belytschko, Liu, Moran & Elkhodary 2014, Table 8.1
KIRSCH_CONCENTRATION = 3.0  # sigma11 / S at the top of the hole (Kirsch 1898)
STRESS_WINDOW = 1.5  # kirsch: the hoop strain is the stretch of the hole's chord within 1.5 h of the point


@dataclass(frozen=True)
class Case:
    """One verification case: its mesh sizes (coarse to fine), the side the hanging family refines
    and the case-specific parameters of its measurement."""

    sizes: tuple
    refine_side: str
    parameters: dict = field(default_factory=dict)


CASES = {
    "cook": Case((2.0, 1.0, 0.5, 0.25), "clamped", {"point": (48.0, 52.0), "corner": (48.0, 60.0)}),
    "kirsch": Case((0.4, 0.2, 0.1, 0.05), "hole", {"hole_side": "hole", "remote_stress": 1.0}),
    "hertz": Case((0.02, 0.01, 0.005), "contact", {"contact_side": "contact", "symmetry_x": None}),
    "lbracket": Case((2.0, 1.0, 0.5), "bottom", {}),
}


def case_scene(name: str, scene_path, family: str, h: float, overrides=()):
    """The scene of one run: the scene file, ``overrides``, then the family (with the case's
    options) at mesh size h."""
    from vemkit.config.scene import load_scene

    mesh = {"family": family, "h": float(h), **FAMILY_OPTIONS[family]}
    if family == "hanging":
        mesh["contact_side"] = CASES[name].refine_side
    return load_scene(scene_path, [*overrides, "discretization.mesh=" + json.dumps(mesh)])


def run_case(name: str, scene_path, family: str, sizes=None, overrides=(), on_solution=None) -> list[dict]:
    """One record per mesh size: the run's size, cost and the case's quantities (see the module doc).

    ``on_solution(h, problem, dataset)`` is called after every solve (e.g. to keep a solution file).
    """
    from vemkit.studies.scene_solve import solve_scene

    records = []
    for level, h in enumerate(CASES[name].sizes if sizes is None else sizes):
        scene = case_scene(name, scene_path, family, h, overrides)
        problem, solution, ds = solve_scene(scene, verify=True)
        record = {
            "scene": name,
            "family": family,
            "level": level,
            "h": float(h),
            "n_cells": problem.mesh.n_cells,
            "n_dofs": int(problem.n_dofs),
            "iterations": int(solution.iterations),
            "wall_time": float(solution.wall_time),
            "check_worst": float(ds.attrs["check_worst"]),
        }
        record.update(MEASURES[name](scene, problem, ds, **CASES[name].parameters))
        records.append(record)
        if on_solution is not None:
            on_solution(h, problem, ds)
    return records


# -- point values ---------------------------------------------------------------------------------
def boundary_value(mesh, u: np.ndarray, point) -> np.ndarray:
    """u_h at a point of the boundary: linear along the boundary edge that holds the point."""
    edges = mesh.boundary_edges
    a, b = mesh.vertices[edges[:, 0]], mesh.vertices[edges[:, 1]]
    d = b - a
    s = np.clip(np.einsum("ij,ij->i", np.asarray(point) - a, d) / np.einsum("ij,ij->i", d, d), 0.0, 1.0)
    gap = np.linalg.norm(a + s[:, None] * d - point, axis=1)
    k = int(np.argmin(gap))
    if gap[k] > 1e-9 * np.ptp(mesh.vertices, axis=0).max():
        raise InputError(
            f"point {tuple(point)} is not on the mesh boundary (nearest edge at {gap[k]:.3g}); give a point of a side",
            key="point",
        )
    return (1.0 - s[k]) * u[edges[k, 0]] + s[k] * u[edges[k, 1]]


def free_boundary_stress(mesh, u: np.ndarray, side: str, point, window: float, E: float) -> float:
    """The tangential stress at ``point`` of a traction-free side, plane stress: σ_tt = E ε_tt
    (σ_nn = σ_nt = 0 there), ε_tt the stretch of the chord between the side's two vertices farthest
    apart along the side within ``window`` of the point: (u_+ - u_-) · (x_+ - x_-) / |x_+ - x_-|²,
    exact for u_h along straight edges, O(window²) from the curvature of the field."""
    verts = mesh.boundary_vertices(side)
    x = mesh.vertices[verts]
    near = np.flatnonzero(np.linalg.norm(x - point, axis=1) <= window)
    if near.size < 2:
        raise InputError(
            f"fewer than 2 vertices of side {side!r} within {window:g} of {tuple(point)}; widen the window",
            key="window",
        )
    tangent = np.linalg.svd(x[near] - x[near].mean(axis=0))[2][0]
    along = (x[near] - point) @ tangent
    lo, hi = verts[near[np.argmin(along)]], verts[near[np.argmax(along)]]
    chord = mesh.vertices[hi] - mesh.vertices[lo]
    return float(E * (u[hi] - u[lo]) @ chord / (chord @ chord))


def _displacement(ds) -> np.ndarray:
    return np.stack([ds["u1"].values, ds["u2"].values], axis=1)


# -- the measurements of each case --------------------------------------------------------------
def cook_quantities(scene, problem, ds, *, point, corner) -> dict:
    u = _displacement(ds)
    v_mid = float(boundary_value(problem.mesh, u, point)[1])
    return {
        "v_mid": v_mid,
        "v_corner": float(boundary_value(problem.mesh, u, corner)[1]),
        "v_mid_reference": COOK_REFERENCE,
        "v_mid_difference": v_mid / COOK_REFERENCE - 1.0,
    }


def kirsch_quantities(scene, problem, ds, *, hole_side, remote_stress) -> dict:
    from vemkit.config.domain import CircleHole, domain_from_spec

    hole = next(h for h in domain_from_spec(scene.domain).holes if isinstance(h, CircleHole) and h.side == hole_side)
    window = STRESS_WINDOW * float(scene.mesh_options["h"])
    sigma = free_boundary_stress(
        problem.mesh, _displacement(ds), hole_side, np.array([hole.cx, hole.cy + hole.r]), window, scene.E
    )
    out = {key: float(ds.attrs[key]) for key in ("error_h1", "error_h1_semi", "error_l2")}
    out.update({"stress_concentration": sigma / remote_stress, "stress_concentration_reference": KIRSCH_CONCENTRATION})
    return out


def arc_radius(domain, side: str) -> float:
    """The radius of the (first) arc of the outer boundary named ``side``."""
    for i, centre in enumerate(domain.arcs):
        if centre is not None and domain.sides[i] == side:
            return math.dist(domain.polygon[i], centre)
    raise InputError(
        f"side {side!r} has no arc: the Hertz comparison needs a curved contact side (domain.arcs)", key="domain.arcs"
    )


def contact_half_width(x: np.ndarray, penetration: np.ndarray, symmetry_x=None) -> float:
    """Half the length (in x) of the contact zone around the deepest point (u_nu - g > 0).

    Each end is extrapolated from the zone's last two vertices with the square-root decay of the
    pressure at the edge of a smooth non-conforming contact (p², hence (u_nu - g)² for m = 1, linear
    in x), kept between the last vertex in contact and the first one out. (Linear interpolation of
    u_nu - g would put the end at the last vertex in contact: outside, the gap opens much faster
    than p/k_nu closes inside, a bias of half a cell.) NaN if the zone reaches an end of Γ_C. With
    ``symmetry_x`` (the contact side is half of a symmetric one): the distance from that axis to the
    end away from it."""
    order = np.argsort(x)
    x, t = x[order], penetration[order]
    peak = int(np.argmax(t))
    if t[peak] <= 0:
        return 0.0
    ends = []
    away = 1 if symmetry_x is None or np.mean(x) >= symmetry_x else -1  # half a zone: walk off the axis only
    for step in (1, -1) if symmetry_x is None else (away,):
        k = peak
        while 0 <= k + step < t.size and t[k + step] > 0:
            k += step
        if not 0 <= k + step < t.size:
            return float("nan")
        inner = k - step if k != peak else k
        shift = (x[k] - x[inner]) * t[k] ** 2 / (t[inner] ** 2 - t[k] ** 2) if t[inner] > t[k] else 0.0
        ends.append(x[k] + float(np.clip(shift, min(0.0, x[k + step] - x[k]), max(0.0, x[k + step] - x[k]))))
    return abs(float(ends[0] - symmetry_x)) if symmetry_x is not None else 0.5 * float(ends[0] - ends[1])


def hertz_quantities(scene, problem, ds, *, contact_side, symmetry_x) -> dict:
    from vemkit.config.domain import domain_from_spec

    cb = problem.contact
    row = {int(v): i for i, v in enumerate(cb.vertices)}
    normal_y = cb.normal[[row[int(v)] for v in ds["contact_vertex"].values], 1]
    pressure, weight = ds["normal_pressure"].values, ds["contact_weight"].values
    mirror = 1.0 if symmetry_x is None else 2.0
    force = mirror * float(np.sum(weight * pressure * -normal_y))
    a = contact_half_width(ds["contact_x"].values, ds["penetration"].values, symmetry_x)
    radius = arc_radius(domain_from_spec(scene.domain), contact_side)
    a_hertz = 2.0 * math.sqrt(radius * force / (math.pi * scene.E))
    p0_hertz = 2.0 * force / (math.pi * a_hertz)
    p0 = float(pressure.max())
    return {
        "contact_force": force,
        "radius": radius,
        "normal_k": float(scene.normal_compliance.k),
        "half_width": a,
        "half_width_hertz": a_hertz,
        "half_width_difference": a / a_hertz - 1.0,
        "peak_pressure": p0,
        "peak_pressure_hertz": p0_hertz,
        "peak_pressure_difference": p0 / p0_hertz - 1.0,
    }


def bracket_quantities(scene, problem, ds) -> dict:
    pressure, weight = ds["normal_pressure"].values, ds["contact_weight"].values
    touching = ds["penetration"].values > 0
    return {
        "contact_force": float(np.sum(weight * pressure)),
        "contact_length": float(np.sum(weight[touching])),
        "max_penetration": float(max(0.0, ds["penetration"].values.max())),
        "max_displacement": float(np.linalg.norm(_displacement(ds), axis=1).max()),
    }


MEASURES = {
    "cook": cook_quantities,
    "kirsch": kirsch_quantities,
    "hertz": hertz_quantities,
    "lbracket": bracket_quantities,
}


# -- the dataset ----------------------------------------------------------------------------------
#: every variable of the verification Dataset: (long name, units)
VARIABLES = {
    "n_cells": ("number of cells", "1"),
    "n_dofs": ("number of unknowns of the discrete problem", "1"),
    "iterations": ("contact solver iterations", "1"),
    "wall_time": ("solver wall time", "s"),
    "check_worst": ("worst residual of the independent check of the solution", "1"),
    "v_mid": ("cook: vertical displacement at the middle of the loaded edge (48, 52)", "length"),
    "v_corner": ("cook: vertical displacement at the top corner of the loaded edge (48, 60)", "length"),
    "v_mid_reference": ("cook: published v(48, 52), Cook 1974 / Belytschko et al. 2014 Table 8.1", "length"),
    "v_mid_difference": ("cook: v_mid / v_mid_reference - 1", "1"),
    "error_h1": ("kirsch: ||Pi_1 u_h - u||_H1 / ||u||_H1 against the exact field", "1"),
    "error_h1_semi": ("kirsch: |Pi_1 u_h - u|_H1 / |u|_H1", "1"),
    "error_l2": ("kirsch: ||Pi_1 u_h - u||_L2 / ||u||_L2", "1"),
    "stress_concentration": ("kirsch: sigma11 / S at the top of the hole, E times the hole's chord stretch", "1"),
    "stress_concentration_reference": ("kirsch: 3, Kirsch 1898", "1"),
    "contact_force": ("total normal contact force P (hertz: of the whole contact, per unit thickness)", "force/length"),
    "radius": ("hertz: radius R of the contact side", "length"),
    "normal_k": ("hertz: normal compliance coefficient k_nu of the foundation", "force/length^3"),
    "half_width": (
        "hertz: contact half-width a (zone ends extrapolated with the square-root pressure decay)",
        "length",
    ),
    "half_width_hertz": ("hertz: 2 sqrt(R P / (pi E*)), E* = E (plane stress)", "length"),
    "half_width_difference": ("hertz: half_width / half_width_hertz - 1", "1"),
    "peak_pressure": ("hertz: largest nodal contact pressure p0", "force/length^2"),
    "peak_pressure_hertz": ("hertz: 2 P / (pi a_H)", "force/length^2"),
    "peak_pressure_difference": ("hertz: peak_pressure / peak_pressure_hertz - 1", "1"),
    "contact_length": ("lbracket: length of Gamma_C in contact (nodal weights of penetrating vertices)", "length"),
    "max_penetration": ("lbracket: largest u_nu - g", "length"),
    "max_displacement": ("lbracket: largest |u|", "length"),
}
#: observed orders: order variable -> the error it is the order of
ORDERS = {"order_h1": "error_h1", "order_h1_semi": "error_h1_semi", "order_l2": "error_l2"}
_IDENTITY = ("scene", "family", "level", "h")


def verification_dataset(records, *, scenes=None, families=None, commit: str | None = None) -> xr.Dataset:
    """The records on the grid scene x family x level (level 0 the coarsest size of each scene),
    with the observed orders of the Kirsch errors (NaN at the coarsest level and where undefined)."""
    records = list(records)
    if not records:
        raise ResultError("no verification records: nothing to gather")
    scenes = list(scenes or dict.fromkeys(r["scene"] for r in records))
    families = list(families or dict.fromkeys(r["family"] for r in records))
    levels = 1 + max(int(r["level"]) for r in records)
    h = np.full((len(scenes), levels), np.nan)
    data = {k: np.full((len(scenes), len(families), levels), np.nan) for k in VARIABLES}
    for r in records:
        unknown = sorted(set(r) - set(VARIABLES) - set(_IDENTITY))
        if unknown:
            raise ResultError(f"verification record {r['scene']}/{r['family']}: unknown quantity {unknown[0]!r}")
        i, j, k = scenes.index(r["scene"]), families.index(r["family"]), int(r["level"])
        h[i, k] = r["h"]
        for key in set(r) - set(_IDENTITY):
            data[key][i, j, k] = float(r[key])
    dims = ("scene", "family", "level")
    ds = xr.Dataset(
        coords={
            "scene": ("scene", np.array(scenes, dtype=str)),
            "family": ("family", np.array(families, dtype=str)),
            "level": ("level", np.arange(levels), {"long_name": "mesh size index, 0 the coarsest"}),
            "h": (
                ("scene", "level"),
                h,
                {"long_name": "mesh size h of discretization.mesh", "units": "length of the scene"},
            ),
        }
    )
    for key, (long_name, units) in VARIABLES.items():
        if np.isfinite(data[key]).any():
            ds[key] = (dims, data[key], {"long_name": long_name, "units": units})
    for name, error in ORDERS.items():
        if error in ds:
            orders = np.array(
                [
                    [convergence_orders(h[i], data[error][i, j]) for j in range(len(families))]
                    for i in range(len(scenes))
                ]
            )
            ds[name] = (
                dims,
                orders,
                {"long_name": f"observed order of {error}: log(e_prev/e) / log(h_prev/h)", "units": "1"},
            )
    versions = package_versions()
    ds.attrs.update(
        {
            "title": "vemkit verification of the shipped scenes",
            "Conventions": "CF-1.8",
            "family_options": json.dumps(FAMILY_OPTIONS),
            "git_commit": commit or git_commit(),
            "package_versions": json.dumps(versions, sort_keys=True),
            "missing_values": "a quantity that does not apply to a scene, or an order at the coarsest "
            "level: NaN in memory, _FillValue -9999.0 in the file",
        }
    )
    return ds


def write_verification(ds: xr.Dataset, path):
    """Write atomically, undefined entries as declared fill values, never NaN."""
    return write_with_fill_values(ds, path)


def read_verification(path) -> xr.Dataset:
    return read_with_fill_values(path)
