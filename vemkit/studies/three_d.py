"""The 3D verification studies (docs/reference/files.md, issue 20 items 7-8): what `snakemake three_d` and
tests/vem3d/test_*closed_forms*.py run.

- Manufactured convergence (:func:`manufactured_run`, :func:`convergence_dataset`): a scene with
  ``exact:`` (config/scenes/3d/box_manufactured.yaml, its body force from
  :func:`manufactured_body_force`) solved on one family at one size, the relative errors of the
  solution file (``error_h1``, ``error_l2``: Pi u_h against u, ``vemkit.vem.norms``).
- Lamé's thick-walled cylinder (:func:`lame_displacement`, :func:`lame_run`): a quarter annulus
  extruded with rollers on the end faces (plane strain) under a bore pressure, against
  u_r = p a² (1 + ν) ((1 − 2ν) r + b²/r) / (E (b² − a²)); the radial displacement error at the bore.
- The extruded body against the 2D models (:func:`base_scene`, :func:`plane_strain_difference`,
  :func:`plane_stress_difference`): a 3D scene on an ``extrude`` domain and the 2D scene of its base
  (the end faces' conditions dropped, the third components dropped), solved on the same base mesh
  (the 3D mesh is the prisms over the 2D family mesh of the same keys, docs/reference/files.md).
- :func:`boundary_polygons`: the boundary faces of a 3D mesh as polygons, for the figures.

Every run returns a plain record (a dict of numbers and strings) and, where asked, the Dataset.
"""

from __future__ import annotations

import copy
import math
import time
from pathlib import Path

import numpy as np

__all__ = [
    "base_scene",
    "boundary_polygons",
    "convergence_dataset",
    "records_dataset",
    "with_solver",
    "lame_displacement",
    "lame_run",
    "load_scene_data",
    "manufactured_body_force",
    "manufactured_run",
    "markdown_table",
    "observed_rates",
    "plane_strain_difference",
    "plane_stress_difference",
    "vertex_match",
    "write_solution_vtu",
]


def load_scene_data(path) -> dict:
    """The mapping of a scene file (plain YAML; validated when a Scene is made of it)."""
    import yaml

    return yaml.safe_load(Path(path).read_text(encoding="utf-8"))


def with_solver(data: dict, solver: dict | None) -> dict:
    """A copy of a scene mapping with ``solver`` (e.g. {linear: amg}) over its solver section."""
    out = copy.deepcopy(data)
    out["solver"] = {**out.get("solver", {}), **dict(solver or {})}
    return out


def _with_mesh(data: dict, **mesh) -> dict:
    """A copy of a scene mapping whose discretization.mesh is ``mesh`` (None values dropped)."""
    out = copy.deepcopy(data)
    out.setdefault("discretization", {})["mesh"] = {k: v for k, v in mesh.items() if v is not None}
    return out


def _solve(data: dict, verify: bool = True):
    from vemkit.config.scene import scene_from_dict
    from vemkit.studies.scene_solve import solve_scene

    t0 = time.perf_counter()
    problem, solution, ds = solve_scene(scene_from_dict(data), verify=verify)
    return problem, solution, ds, time.perf_counter() - t0


# --------------------------------------------------------------------------------------------
# manufactured convergence
# --------------------------------------------------------------------------------------------
def manufactured_body_force(u, E: float, nu: float) -> list[str]:
    """f = -div C eps(u) (3D isotropic C of E, nu) of u = three expressions in x, y, z, exactly
    (sympy), as expressions of the scene language."""
    import sympy as sp

    X = sp.symbols("x y z")
    E, nu = sp.nsimplify(E), sp.nsimplify(nu)
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    field = sp.Matrix([sp.sympify(c, locals=dict(zip("xyz", X, strict=True))) for c in u])
    grad = field.jacobian(X)
    eps = (grad + grad.T) / 2
    sigma = lam * eps.trace() * sp.eye(3) + 2 * mu * eps
    force = [-sum(sp.diff(sigma[i, j], X[j]) for j in range(3)) for i in range(3)]
    return [sp.sstr(sp.simplify(f)) for f in force]


def manufactured_run(data: dict, family: str, n, options: dict | None = None):
    """One solve of a scene with ``exact:`` on ``family`` at size ``n``: (record, problem, dataset)."""
    run = _with_mesh(data, family=family, n=n, **dict(options or {}))
    problem, solution, ds, wall = _solve(run)
    record = {
        "family": family,
        "n": n,
        "cells": int(problem.mesh.n_cells),
        "vertices": int(problem.mesh.n_vertices),
        "dofs": int(problem.n_dofs),
        "h_max": float(np.max(problem.mesh.cell_diameters)),
        "error_h1": float(ds.attrs["error_h1"]),
        "error_h1_semi": float(ds.attrs["error_h1_semi"]),
        "error_l2": float(ds.attrs["error_l2"]),
        "wall_time": wall,
    }
    return record, problem, ds


def observed_rates(errors, sizes) -> np.ndarray:
    """Rates log(e_{i-1}/e_i) / log(s_i/s_{i-1}) between consecutive sizes (NaN first): with
    ``sizes`` = n (cells per unit length), the order in h = 1/n."""
    e, s = np.asarray(errors, float), np.asarray(sizes, float)
    return np.concatenate([[np.nan], np.log(e[:-1] / e[1:]) / np.log(s[1:] / s[:-1])])


def convergence_dataset(records, families, attrs: dict | None = None):
    """One Dataset (family x level) of the manufactured runs: n, cells, dofs, h_max, the errors,
    their rates in h = 1/n and per DOF (order in h of dofs^(-1/3)); ``order_h1``/``order_l2`` per
    family: the rate in the mean cell size (cells^(-1/3)) between the two finest levels."""
    import xarray as xr

    by_family = {f: sorted((r for r in records if r["family"] == f), key=lambda r: float(r["n"])) for f in families}
    levels = max(len(v) for v in by_family.values())
    keys = ("n", "cells", "vertices", "dofs", "h_max", "error_h1", "error_h1_semi", "error_l2", "wall_time")
    data = {k: np.full((len(families), levels), np.nan) for k in keys}
    for i, f in enumerate(families):
        for j, r in enumerate(by_family[f]):
            for k in keys:
                data[k][i, j] = r[k]
    variables = {k: (("family", "level"), v) for k, v in data.items()}
    for norm in ("h1", "l2"):
        e = data[f"error_{norm}"]
        variables[f"rate_{norm}"] = (
            ("family", "level"),
            np.stack([observed_rates(e[i], data["n"][i]) for i in range(len(families))]),
        )
        variables[f"rate_{norm}_dofs"] = (
            ("family", "level"),
            np.stack([observed_rates(e[i], data["dofs"][i] ** (1.0 / 3.0)) for i in range(len(families))]),
        )
        variables[f"rate_{norm}_cells"] = (
            ("family", "level"),
            np.stack([observed_rates(e[i], data["cells"][i] ** (1.0 / 3.0)) for i in range(len(families))]),
        )
        # the order in the mean cell size (|Omega| / cells)^(1/3): gmsh's tetrahedra and the octree's
        # refinement do not scale their cell counts as n^3, so 1/n is no measure of h there
        variables[f"order_{norm}"] = (("family",), variables[f"rate_{norm}_cells"][1][:, -1])
    ds = xr.Dataset(variables, coords={"family": list(families), "level": np.arange(levels)}, attrs=dict(attrs or {}))
    ds["rate_h1"].attrs["long_name"] = "observed order of error_h1 in h = 1/n between consecutive levels"
    ds["rate_h1_dofs"].attrs["long_name"] = "observed order of error_h1 in dofs^(-1/3)"
    ds["rate_h1_cells"].attrs["long_name"] = "observed order of error_h1 in the mean cell size cells^(-1/3)"
    ds["error_h1"].attrs["long_name"] = "||Pi u_h - u||_1 / ||u||_1"
    ds["error_l2"].attrs["long_name"] = "||Pi u_h - u||_0 / ||u||_0"
    return ds


# --------------------------------------------------------------------------------------------
# Lamé's cylinder
# --------------------------------------------------------------------------------------------
def lame_displacement(r, a: float, b: float, p: float, E: float, nu: float):
    """Plane-strain radial displacement of a thick-walled cylinder (radii a < b) under internal
    pressure p: u_r = p a² (1 + ν) ((1 − 2ν) r + b²/r) / (E (b² − a²))."""
    r = np.asarray(r, float)
    return p * a * a * (1 + nu) * ((1 - 2 * nu) * r + b * b / r) / (E * (b * b - a * a))


def lame_run(
    data: dict,
    family: str,
    h: float,
    layers: int | None = 1,
    a: float = 1.0,
    b: float = 2.0,
    p: float = 1.0,
    seed: int | None = None,
):
    """One solve of the Lamé scene (config/scenes/3d/lame.yaml) at cell size h: (record, problem,
    dataset); the record has the scene's relative errors and ``bore_error``, the largest relative
    error of u_r = (u1 x + u2 y)/r over the bore's vertices (which lie on r = a)."""
    E, nu = float(data["material"]["E"]), float(data["material"]["nu"])
    problem, solution, ds, wall = _solve(_with_mesh(data, family=family, h=h, layers=layers, seed=seed))
    x, y = ds["mesh3d_node_x"].values, ds["mesh3d_node_y"].values
    r = np.hypot(x, y)
    ur = (ds["u1"].values * x + ds["u2"].values * y) / r
    bore = np.abs(r - a) < 1e-9 * a
    exact = lame_displacement(a, a, b, p, E, nu)
    record = {
        "family": family,
        "h": float(h),
        "layers": int(layers or 0),
        "cells": int(problem.mesh.n_cells),
        "dofs": int(problem.n_dofs),
        "error_h1": float(ds.attrs["error_h1"]),
        "error_l2": float(ds.attrs["error_l2"]),
        "bore_error": float(np.max(np.abs(ur[bore] - exact)) / exact),
        "bore_vertices": int(bore.sum()),
        "u3_max": float(np.max(np.abs(ds["u3"].values))),
        "wall_time": wall,
    }
    return record, problem, ds


# --------------------------------------------------------------------------------------------
# the extruded body against the 2D models
# --------------------------------------------------------------------------------------------
def _drop_third(value):
    return list(value[:2]) if isinstance(value, (list, tuple)) and len(value) == 3 else value


def base_scene(data: dict, model: str) -> dict:
    """The 2D scene (``model``: plane_strain or plane_stress) of the base of a 3D scene on an
    ``extrude`` domain: the same polygon, sides, material, mesh keys (``layers`` dropped), the
    lateral sides' conditions without their third component, the end faces' conditions dropped."""
    out = copy.deepcopy(data)
    domain = out["domain"]
    ends = tuple(domain.pop("extrude").get("ends", ("front", "back")))
    out["model"] = model
    out["name"] = f"{data.get('name', 'scene')}_{model}"
    if "body_force" in out:
        out["body_force"] = _drop_third(out["body_force"])
    boundary = out.get("boundary", {})
    dirichlet = boundary.get("dirichlet")
    if isinstance(dirichlet, dict):
        boundary["dirichlet"] = {s: _drop_third(v) for s, v in dirichlet.items() if s not in ends}
    elif isinstance(dirichlet, list):
        boundary["dirichlet"] = [s for s in dirichlet if s not in ends]
    for side, load in list(boundary.get("neumann", {}).items()):
        if side in ends:
            del boundary["neumann"][side]
        elif "traction" in load:
            load["traction"] = _drop_third(load["traction"])
    if "exact" in out:
        out["exact"]["displacement"] = _drop_third(out["exact"]["displacement"])
    out.get("discretization", {}).get("mesh", {}).pop("layers", None)
    return out


def vertex_match(base_xy: np.ndarray, xy: np.ndarray, tol: float = 1e-12) -> np.ndarray:
    """For every point of ``xy`` (P, 2) the index of the base vertex at the same (x, y); ValueError
    when one has none within ``tol`` times the body's size (the meshes are not prisms over the base)."""
    from scipy.spatial import cKDTree

    distance, index = cKDTree(base_xy).query(xy)
    scale = float(np.ptp(base_xy, axis=0).max())
    if distance.max() > tol * scale:
        raise ValueError(f"a 3D vertex is {distance.max():.3g} from every base vertex: not prisms over the base mesh")
    return index


def _vertices(ds, topology: str) -> np.ndarray:
    return np.stack([ds[f"{topology}_node_x"].values, ds[f"{topology}_node_y"].values], axis=1)


def _compare(ds2, ds3, average: bool):
    """(max relative difference, rms relative difference, base vertices) of u1, u2 of the 3D
    solution (at every vertex of every layer; ``average``: the thickness average per base vertex)
    against the 2D solution at the same base vertex."""
    base = _vertices(ds2, "mesh2d")
    index = vertex_match(base, _vertices(ds3, "mesh3d"))
    u2 = np.stack([ds2["u1"].values, ds2["u2"].values], axis=1)
    u3 = np.stack([ds3["u1"].values, ds3["u2"].values], axis=1)
    if average:
        mean, count = np.zeros_like(u2), np.zeros(len(u2))
        np.add.at(mean, index, u3)
        np.add.at(count, index, 1.0)
        diff = mean / count[:, None] - u2
    else:
        diff = u3 - u2[index]
    scale = np.abs(u2).max()
    rms = math.sqrt(np.mean(np.sum(diff**2, axis=1)) / np.mean(np.sum(u2**2, axis=1)))
    return float(np.abs(diff).max() / scale), rms, len(base)


def plane_strain_difference(
    data: dict, family: str, n, layers: int, stabilization: str | None = None, seed: int | None = None
):
    """The 3D scene ``data`` (extrude domain, rollers u3 = 0 on both end faces) against its base's
    ``plane_strain`` scene on the same base mesh: record with ``max_difference`` = max over every
    vertex of every layer of |u_3D - u_2D| (u1, u2) / max |u_2D|; and the two Datasets."""
    run = _with_mesh(data, family=family, n=n, layers=layers, seed=seed)
    if stabilization is not None:
        run["discretization"]["stabilization"] = stabilization
    solved, ds2, ds3 = _against_base(run, "plane_strain", average=False)
    record = {
        "family": family,
        "n": n,
        "layers": layers,
        "stabilization": run["discretization"].get("stabilization", ""),
        "cells_2d": solved["cells_2d"],
        **{key: solved[key] for key in DIFFERENCE_KEYS},
        "u3_max": float(np.abs(ds3["u3"].values).max()),
        "wall_time": solved["wall_time"],
    }
    return record, ds2, ds3


def plane_stress_difference(
    data: dict, family: str, depth: float, cells_per_depth: float = 1.0, layers: int = 1, n=None
):
    """The 3D scene ``data`` (extrude domain, traction-free end faces) at ``depth`` against its base's
    ``plane_stress`` scene on the same base mesh: the thickness average of u1, u2 per base vertex
    against the 2D solution, relative to max |u_2D|. The base mesh has n = cells_per_depth / depth
    (prisms of a fixed shape as the depth shrinks) unless ``n`` is given (a fixed base mesh)."""
    run = copy.deepcopy(data)
    run["domain"]["extrude"]["depth"] = float(depth)
    n = max(1, int(round(cells_per_depth / depth))) if n is None else n
    run = _with_mesh(run, family=family, n=n, layers=layers)
    solved, ds2, ds3 = _against_base(run, "plane_stress", average=True)
    differences = {key: solved[key] for key in DIFFERENCE_KEYS}
    record = {"family": family, "depth": float(depth), "n": n, "layers": layers, **differences}
    return record | {"wall_time": solved["wall_time"]}, ds2, ds3


#: what a record of the 3D body beside its plane base says of the two solves (``_against_base``)
DIFFERENCE_KEYS = ("cells_3d", "dofs_3d", "max_difference", "rms_difference")


def _against_base(run: dict, model: str, average: bool):
    """(solved, ds2, ds3) of the 3D scene ``run`` solved beside its base's ``model`` scene: the cells
    and unknowns, the max and rms relative difference of u1, u2 (``_compare``) and the wall time."""
    p2, _, ds2, wall2 = _solve(base_scene(run, model))
    p3, _, ds3, wall3 = _solve(run)
    worst, rms, _vertices = _compare(ds2, ds3, average=average)
    solved = {
        "cells_2d": int(p2.mesh.n_cells),
        "cells_3d": int(p3.mesh.n_cells),
        "dofs_3d": int(p3.n_dofs),
        "max_difference": worst,
        "rms_difference": rms,
        "wall_time": wall2 + wall3,
    }
    return solved, ds2, ds3


# --------------------------------------------------------------------------------------------
# tables and figures
# --------------------------------------------------------------------------------------------
def markdown_table(records, columns, headers=None, formats=None) -> str:
    """A Markdown table of ``records`` (dicts): ``columns`` keys, ``formats`` key -> format spec."""
    headers = headers or columns
    formats = formats or {}

    def cell(r, k):
        v = r.get(k, "")
        if isinstance(v, float) and not math.isfinite(v):
            return "-"
        return format(v, formats.get(k, ".3g" if isinstance(v, float) else ""))

    lines = ["| " + " | ".join(headers) + " |", "|" + "|".join("---" for _ in columns) + "|"]
    lines += ["| " + " | ".join(cell(r, k) for k in columns) + " |" for r in records]
    return "\n".join(lines) + "\n"


def records_dataset(records, dims, attrs: dict | None = None):
    """A Dataset of ``records`` (dicts) on the grid of the distinct values of the keys ``dims`` (in
    order of first appearance); every other numeric key becomes a variable (NaN where no record)."""
    import xarray as xr

    coords = {d: list(dict.fromkeys(r[d] for r in records)) for d in dims}
    shape = tuple(len(coords[d]) for d in dims)
    names = [k for k in records[0] if k not in dims and isinstance(records[0][k], (int, float))]
    data = {k: np.full(shape, np.nan) for k in names}
    for r in records:
        at = tuple(coords[d].index(r[d]) for d in dims)
        for k in names:
            data[k][at] = r[k]
    return xr.Dataset({k: (tuple(dims), v) for k, v in data.items()}, coords=coords, attrs=dict(attrs or {}))


def write_solution_vtu(mesh, ds, path) -> None:
    """The solution Dataset ``ds`` (mesh3d) on ``mesh`` as VTK polyhedra: point data displacement
    (n, 3), cell data von_mises and the stress and strain components."""
    from vemkit.mesh.vtu import write_vtu

    u = np.stack([ds[c].values for c in ("u1", "u2", "u3")], axis=1)
    cells = {k: ds[k].values for k in ds.data_vars if k == "von_mises" or k.startswith(("stress_", "strain_"))}
    write_vtu(mesh, path, point_data={"displacement": u}, cell_data=cells)


def boundary_polygons(mesh, displacement=None, scale: float = 1.0):
    """(polygons, cells): every boundary face of a 3D mesh as an (m, 3) array of its (displaced by
    ``scale`` x ``displacement`` (n_vertices, 3)) corners, and the cell it bounds."""
    x = mesh.vertices if displacement is None else mesh.vertices + scale * np.asarray(displacement, float)
    faces = np.asarray(mesh.boundary_faces, dtype=np.int64)
    cells = mesh.face_cells[faces]
    owner = np.where(cells[:, 0] >= 0, cells[:, 0], cells[:, 1])
    return [x[mesh.face(f)] for f in faces], owner
