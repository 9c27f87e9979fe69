"""Parameter sweeps: a grid of scene parameters -> one Dataset with the parameters as dimensions.

A grid maps scene keys (as ``--set``) to lists of values, e.g.
``{"contact.friction.k": [0, 100, 450], "contact.normal.k": [1, 10, 100]}``; every combination is
one point. Points that differ only in ``contact.*`` (gap, normal, friction) or ``solver.*`` share
the assembled problem: K and the load are assembled once per combination of the other keys
(material, discretization), the mesh once per ``discretization.mesh``, and one linear solver
(factorization or AMG hierarchy) is built per assembled problem and handed to the contact solver
when it takes a prebuilt one (``vemkit.studies.robustness.prebuilt_linear_supported``). Each point gets
``dataclasses.replace(problem, law=..., contact=...)``.

Per point (see ``vemkit.studies.sweep_quantities``): max penetration max (u_nu - g)_+, contact length (sum of the
nodal weights where u_nu - g > 0), stick and slip lengths (``contact_state``), resultant normal
force sum w p_nu and tangential force sum w sigma_tau (over all Gamma_C vertices: with the
reduced law m_tau = 0 the friction bound acts on separated vertices too), iterations, wall time,
the independent check and a status code (``vemkit.studies.robustness.STATUS_MEANINGS``). With a fixed
mesh, the contact-boundary profiles (pressure, tangential stress, slip, penetration, multiplier,
state) along Gamma_C, dims grid + ``contact_node``.

Missing values. A point that is not ``converged`` (status != 0) has no physical quantities and
no profile: in memory NaN (floats) and -1 (integers, state); in the file (:func:`write_dataset`)
the float variables holding them carry ``_FillValue = -9999.0`` and the integer ones
``_FillValue = -1``; no NaN is stored. ``valid`` (int8) marks the converged points. Wall time,
status and message are defined everywhere; iterations where the solver named them.
"""

from __future__ import annotations

import itertools
import json
import time
from dataclasses import replace

import numpy as np
import xarray as xr

from vemkit.io.fill_values import FLOAT_FILL, INT_FILL, read_with_fill_values, write_with_fill_values
from vemkit.io.provenance import package_versions
from vemkit.solvers.verification import DEFAULT_CHECK_TOL, Outcome, failed, guarded_solve
from vemkit.studies.robustness import status_attributes
from vemkit.studies.sweep_dimensions import dimension_name
from vemkit.studies.sweep_quantities import (  # noqa: F401  (QUANTITIES*: re-exported)
    CONTACT_GEOMETRY,
    PROFILES,
    QUANTITIES,
    QUANTITIES_3D,
    coordinate_names,
    point_quantities,
)

SHARED_PREFIXES = ("contact.", "solver.")  # keys that leave K, the load and the mesh unchanged


def normalize_grid(grid) -> dict:
    """{scene key: tuple of values}, checked: non-empty, distinct values, distinct dimension names."""
    if not isinstance(grid, dict) or not grid:
        raise ValueError("a sweep grid maps scene keys to lists of values, e.g. {'contact.normal.k': [1, 10]}")
    out, names = {}, {}
    for key, values in grid.items():
        values = tuple(values) if isinstance(values, (list, tuple)) else (values,)
        if not values:
            raise ValueError(f"sweep grid {key}: give at least one value")
        if len(set(map(json.dumps, values))) != len(values):
            raise ValueError(f"sweep grid {key}: a value is listed twice")
        name = dimension_name(key)
        if name in names:
            raise ValueError(f"sweep grid {key} and {names[name]} have the same dimension name {name!r}")
        out[str(key)], names[name] = values, key
    return out


def split_grid(grid, parts: int) -> list[dict]:
    """The grid cut into up to ``parts`` contiguous pieces along its first dimension of length >= 2."""
    grid = normalize_grid(grid)
    key = next((k for k, v in grid.items() if len(v) >= 2), None)
    if key is None or parts <= 1:
        return [grid]
    chunks = [c for c in np.array_split(np.arange(len(grid[key])), min(parts, len(grid[key]))) if c.size]
    return [{**grid, key: tuple(grid[key][i] for i in chunk)} for chunk in chunks]


def _override(key, value) -> str:
    return f"{key}={json.dumps(value)}"


class _Point:
    """What one grid point produced: the outcome and, when converged, its quantities and profiles."""

    def __init__(self, outcome: Outcome, n_dofs=-1, quantities=None, profiles=None, setup_time=0.0, dimension=2):
        self.outcome, self.n_dofs, self.setup_time, self.dimension = outcome, n_dofs, setup_time, dimension
        self.quantities, self.profiles = quantities or {}, profiles


def _contact_problem(problem, scene):
    """``problem`` with the contact law and gap of ``scene`` (K, load and mesh unchanged)."""
    from vemkit.contact.laws import contact_law
    from vemkit.contact.problem import scene_gap

    normal, friction = scene.normal_compliance, scene.friction_bound
    law = contact_law(normal, friction)
    contact = problem.contact.with_gap(scene_gap(scene))  # a foundation or an expression, 2D or 3D
    return replace(problem, law=law, contact=contact, info=dict(problem.info))


def run_grid(scene, grid, *, reuse=True, time_budget=None, check_tol=DEFAULT_CHECK_TOL, progress=None) -> dict:
    """Solve every point of ``grid`` on ``scene`` (a ``vemkit.config.scene.Scene``): {index tuple: _Point}.

    ``reuse=False`` builds mesh, problem and linear solver afresh for every point (for comparison).
    progress(index, values, point) after each point.
    """
    from vemkit.contact.problem import scene_problem
    from vemkit.mesh.meshing import scene_mesh

    grid = normalize_grid(grid)
    keys = list(grid)
    shared = [k for k in keys if k.startswith(SHARED_PREFIXES)] if reuse else []
    own = [k for k in keys if k not in shared]
    meshes, results = {}, {}
    for own_values in itertools.product(*(range(len(grid[k])) for k in own)):
        t0 = time.perf_counter()
        problem, error, linear = None, None, {}
        try:
            group = scene.with_overrides([_override(k, grid[k][i]) for k, i in zip(own, own_values)])
            mesh_key = json.dumps(group.mesh_options, sort_keys=True)
            if mesh_key not in meshes:
                meshes[mesh_key] = scene_mesh(group) if reuse else None
            problem = scene_problem(group, meshes[mesh_key])
        except Exception as exc:  # noqa: BLE001 - the whole group fails, classified
            error = exc
        setup = time.perf_counter() - t0  # paid by the group's first point
        for shared_values in itertools.product(*(range(len(grid[k])) for k in shared)):
            index_of = dict(zip(own, own_values)) | dict(zip(shared, shared_values))
            index = tuple(index_of[k] for k in keys)
            values = {k: grid[k][index_of[k]] for k in keys}
            if error is not None:
                point = _Point(failed(str(group_method(scene, values)), error, "setup"))
            else:
                point = _solve_point(group, problem, shared, values, linear if reuse else None, time_budget, check_tol)
            point.setup_time += setup
            setup = 0.0
            results[index] = point
            if progress is not None:
                progress(index, values, point)
    return results


def group_method(scene, values) -> str:
    return values.get("solver.method", scene.solver_options.get("method", "ssn"))


def _solve_point(group, problem, shared, values, linear_cache, time_budget, check_tol) -> _Point:
    from vemkit.solvers.linear import linear_solver
    from vemkit.solvers.verification import prebuilt_linear_supported

    method = str(group_method(group, values))
    try:
        point_scene = group.with_overrides([_override(k, values[k]) for k in shared]) if shared else group
        point_problem = _contact_problem(problem, point_scene) if shared else problem
        options = point_scene.solver_options
        linear = None
        t0 = time.perf_counter()
        if linear_cache is not None and prebuilt_linear_supported():
            key = (options.get("linear", "auto"), float(options["tol"]))
            if key not in linear_cache:
                linear_cache[key] = linear_solver(
                    problem.stiffness, key[0], near_nullspace=problem.near_nullspace, tol=key[1]
                )
            linear = linear_cache[key]
        linear_setup = time.perf_counter() - t0
    except Exception as exc:  # noqa: BLE001
        return _Point(failed(method, exc, "setup"), problem.n_dofs)
    outcome = guarded_solve(point_problem, options, linear=linear, time_budget=time_budget, check_tol=check_tol)
    if not outcome.converged:
        return _Point(outcome, problem.n_dofs, setup_time=linear_setup)
    quantities, profiles = point_quantities(point_problem, outcome)
    return _Point(outcome, problem.n_dofs, quantities, profiles, linear_setup, problem.contact.dimension)


def _coordinate(key, values):
    if all(isinstance(v, (int, np.integer)) and not isinstance(v, bool) for v in values):
        data = np.asarray(values, dtype=np.int64)
    elif all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        data = np.asarray(values, dtype=float)
    else:
        data = np.asarray([v if isinstance(v, str) else json.dumps(v) for v in values], dtype=object)
    return data, {"long_name": f"scene parameter {key}", "scene_key": key}


def sweep_dataset(results: dict, grid, *, scene_yaml: str = "", attrs=None) -> xr.Dataset:
    """The Dataset of :func:`run_grid` results: dims = the grid's (in order) [+ ``contact_node``]."""
    import vemkit

    grid = normalize_grid(grid)
    dims = tuple(dimension_name(k) for k in grid)
    shape = tuple(len(v) for v in grid.values())
    coords = {dimension_name(k): (dimension_name(k), *_coordinate(k, v)) for k, v in grid.items()}
    ds = xr.Dataset(coords=coords)
    status = np.zeros(shape, np.int8)
    iterations = np.full(shape, INT_FILL, np.int64)
    n_dofs = np.full(shape, INT_FILL, np.int64)
    wall, setup = np.zeros(shape), np.zeros(shape)
    messages = np.full(shape, "", dtype=object)
    dimension = max((p.dimension for p in results.values()), default=2)
    geometry, axes = CONTACT_GEOMETRY[dimension], coordinate_names(dimension)
    table = geometry.quantities
    quantities = {k: np.full(shape, np.nan) for k in table}
    profiles = [p.profiles for p in results.values() if p.profiles is not None]
    sizes = {p["x"].tobytes() + p["y"].tobytes() for p in profiles}
    keep_profiles = len(sizes) == 1
    n_c = len(profiles[0]["x"]) if keep_profiles else 0
    # tangential profiles of a solid have d - 1 components in the vertex basis (contact_tangent,
    # docs/reference/files.md); a plane body's one is squeezed (as_written)
    tangent_shape = {k: np.shape(profiles[0][k])[1:] for k in PROFILES} if keep_profiles else {}
    profile_data = {k: np.full(shape + (n_c,) + tangent_shape.get(k, ()), np.nan) for k in PROFILES}
    state = np.full(shape + (n_c,), INT_FILL, np.int8)
    for index, point in results.items():
        o = point.outcome
        status[index], iterations[index], n_dofs[index] = o.code, o.iterations, point.n_dofs
        wall[index], setup[index], messages[index] = o.wall_time, point.setup_time, o.message
        for k, v in point.quantities.items():
            quantities[k][index] = v
        if keep_profiles and point.profiles is not None:
            for k in PROFILES:
                profile_data[k][index] = point.profiles[k]
            state[index] = point.profiles["state"]
    ds["status"] = (dims, status, status_attributes("outcome of the point"))
    ds["valid"] = (
        dims,
        (status == 0).astype(np.int8),
        {
            "long_name": "1 where the point converged and passed the check",
            "flag_values": np.array([0, 1], np.int8),
            "flag_meanings": "invalid valid",
        },
    )
    for k, (long_name, units) in table.items():
        ds[k] = (dims, quantities[k], {"long_name": long_name, "units": units})
    ds["iterations"] = (dims, iterations, {"long_name": "nonlinear iterations (-1: unknown)"})
    ds["n_dofs"] = (dims, n_dofs, {"long_name": "free unknowns (-1: not assembled)"})
    ds["wall_time"] = (dims, wall, {"long_name": "wall time of the contact solve", "units": "s"})
    ds["setup_time"] = (
        dims,
        setup,
        {"long_name": "mesh, assembly and linear solver set-up paid at this point (0 where reused)", "units": "s"},
    )
    ds["message"] = (dims, messages, {"long_name": "failure message (empty when converged)"})
    if keep_profiles:
        first = profiles[0]

        def coordinate(axis):
            return ("contact_node", first[axis], {"long_name": f"{axis} of the contact vertex", "units": "mm"})

        weight = ("contact_node", first["w"], {"long_name": "nodal quadrature weight", "units": geometry.measure_units})
        # the file's order: the plane's coordinates, the weight, then z
        ds = ds.assign_coords({f"contact_{a}": coordinate(a) for a in axes[:2]} | {"contact_weight": weight})
        ds = ds.assign_coords({f"contact_{a}": coordinate(a) for a in axes[2:]})
        pdims = dims + ("contact_node",)
        for k, (_, long_name, units) in PROFILES.items():
            extra = ("contact_tangent",) if tangent_shape.get(k) else ()
            meta = {"long_name": long_name, "units": units}
            if extra:
                meta["comment"] = (
                    "components along the vertex's tangent basis (t1, t2) of the solution file (docs/reference/files.md)"
                )
            ds[f"profile_{k}"] = (pdims + extra, profile_data[k], meta)
        ds["profile_state"] = (
            pdims,
            state,
            {
                "long_name": "contact state along Gamma_C (-1: no solution)",
                "flag_values": np.array([0, 1, 2], np.int8),
                "flag_meanings": "separated stick slip",
            },
        )
    ds.attrs.update(
        {
            "title": "vemkit parameter sweep",
            "Conventions": "CF-1.8",
            "scene": scene_yaml,
            "grid": json.dumps({k: list(v) for k, v in grid.items()}),
            "points": int(np.prod(shape)),
            "converged_points": int(np.sum(status == 0)),
            "profiles": f"along Gamma_C (contact_node ordered by {', '.join(axes)})"
            if keep_profiles
            else "omitted: the grid changes the contact nodes (mesh)"
            if sizes
            else "omitted: no converged point",
            "missing_values": f"not converged points (valid = 0): float _FillValue {FLOAT_FILL}, integer {INT_FILL}; no NaN stored",
            "vemkit_version": vemkit.__version__,
            "package_versions": json.dumps(package_versions(), sort_keys=True),
        }
    )
    ds.attrs.update(attrs or {})
    return ds


def run_sweep(
    scene, grid, *, reuse=True, time_budget=None, check_tol=DEFAULT_CHECK_TOL, progress=None, attrs=None
) -> xr.Dataset:
    """run_grid + sweep_dataset; the attributes record the solver options, reuse and timing."""
    from vemkit.solvers.verification import prebuilt_linear_supported

    t0 = time.perf_counter()
    results = run_grid(scene, grid, reuse=reuse, time_budget=time_budget, check_tol=check_tol, progress=progress)
    info = {
        "solver_options": json.dumps(scene.solver_options, sort_keys=True, default=str),
        "reuse": json.dumps({"problem": bool(reuse), "linear_solver": bool(reuse and prebuilt_linear_supported())}),
        "time_budget": float(time_budget) if time_budget is not None else 0.0,
        "check_tol": float(check_tol),
        "total_time": time.perf_counter() - t0,
    }
    return sweep_dataset(results, grid, scene_yaml=scene.to_yaml(), attrs={**info, **(attrs or {})})


def write_dataset(ds: xr.Dataset, path):
    """Write atomically; undefined entries as declared fill values (``vemkit.io.fill_values``)."""
    return write_with_fill_values(ds, path)


def read_dataset(path) -> xr.Dataset:
    """Read a file written by :func:`write_dataset`: float fill values back to NaN, integer ones kept as -1."""
    return read_with_fill_values(path)


def combine_parts(parts) -> xr.Dataset:
    """The Datasets of a grid split by :func:`split_grid` (in order) joined along the split dimension."""
    parts = list(parts)
    if len(parts) == 1:
        return parts[0]
    grids = [json.loads(p.attrs["grid"]) for p in parts]
    key = next(k for k in grids[0] if any(g[k] != grids[0][k] for g in grids))
    dim = dimension_name(key)
    ds = xr.concat(
        parts,
        dim=dim,
        data_vars="minimal",
        coords="minimal",
        compat="override",
        join="override",
        combine_attrs="override",
    )
    grid = dict(grids[0])
    grid[key] = [v for g in grids for v in g[key]]
    status = ds["status"].values
    ds.attrs.update(
        {
            "grid": json.dumps(grid),
            "points": int(status.size),
            "converged_points": int(np.sum(status == 0)),
            "total_time": float(sum(p.attrs.get("total_time", 0.0) for p in parts)),
            "parts": len(parts),
        }
    )
    return ds
