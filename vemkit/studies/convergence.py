"""Convergence studies: per-run error records -> one self-describing ``xarray.Dataset``.

A *record* is one coarse solve compared with the reference solution of the same stabilization
(SPEC §5): a dict with the keys of :data:`RECORD_KEYS`. :func:`error_records` computes them from
solution files, :func:`convergence_dataset` gathers them on the grid ``family x stabilization x
h`` and :func:`write_convergence` stores the result as netCDF4.

Missing values are explicit, never a quiet NaN in the file. Two kinds of entries are undefined:
the convergence ``order`` at the coarsest ``h`` of every (family, stabilization) (an order needs
two levels), and every variable where a family has no mesh at that ``h``. In memory they are NaN
(floats) or -1 (integers); on disk those values are replaced by the variable's declared
``_FillValue`` (-9999.0 for floats, -1 for integers; CF convention), so ``xarray.open_dataset``
masks them back to NaN and ``netCDF4`` returns masked arrays. Variables without undefined
entries declare no ``_FillValue``. The variable ``defined`` (int8) marks the existing runs and
``order_defined`` the entries where an order is defined.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import xarray as xr

from vemkit.io.fill_values import FLOAT_FILL, INT_FILL, read_with_fill_values, write_with_fill_values
from vemkit.io.provenance import git_commit, package_versions
from vemkit.io.solution_file import read_solution
from vemkit.studies.solution_order import projected_solution_file, refuse_order2, require_order1, solution_order  # noqa: F401

#: keys of one error record, with their meaning and units
RECORD_KEYS = {
    "family": ("mesh family label (config meshes)", None),
    "stabilization": ("stabilization of the VEM bilinear form (and of the reference)", None),
    "n": ("cells per side, n = 1/h", "1"),
    "h": ("nominal mesh size 1/n", "mm"),
    "h_max": ("largest cell diameter of the mesh", "mm"),
    "n_cells": ("number of cells", "1"),
    "n_dofs": ("number of free displacement unknowns", "1"),
    "error_h1": ("||Pi_1(u_h - u_ref)||_H1 / ||Pi_1 u_ref||_H1 (full H1 norm, broken, SPEC 5)", "1"),
    "error_h1_semi": ("|Pi_1(u_h - u_ref)|_H1 / |Pi_1 u_ref|_H1 (H1 seminorm, broken, SPEC 5)", "1"),
    "error_l2": ("||Pi_1(u_h - u_ref)||_L2 / ||Pi_1 u_ref||_L2", "1"),
    "error_paper": (
        "|Pi_1^ref(I_ref u_h - u_ref)|_H1 / |Pi_1^ref u_ref|_H1: the paper's measure, I_ref the "
        "interpolant at the reference vertices (bilinear on squares, Wachspress / mean value "
        "coordinates elsewhere), H1 seminorm broken over the reference cells (SPEC 5)",
        "1",
    ),
    "iterations": ("nonlinear contact solver iterations", "1"),
    "wall_time": ("contact solver wall time (with the linear solver set-up)", "s"),
    "assembly_time": ("assembly wall time of the discrete problem", "s"),
}
_VARIABLES = (
    "error_h1",
    "error_h1_semi",
    "error_l2",
    "error_paper",
    "n_dofs",
    "n_cells",
    "iterations",
    "wall_time",
    "assembly_time",
    "h_max",
)


# -- orders ---------------------------------------------------------------------------------------
def convergence_orders(h, errors) -> np.ndarray:
    """Observed orders log(e_{k-1}/e_k) / log(h_{k-1}/h_k) between successive levels.

    ``h`` and ``errors`` are in the order of the levels (coarse to fine, or any order: the levels
    are sorted by decreasing h first). Levels whose error is NaN are skipped; the order of a level
    is taken against the next coarser level that has an error. The first (coarsest) level, and a
    level whose error or predecessor's error is not positive, gets NaN. The result is aligned
    with the input.
    """
    h = np.asarray(h, dtype=float)
    e = np.asarray(errors, dtype=float)
    out = np.full(h.shape, np.nan)
    previous = None
    for k in np.argsort(-h, kind="stable"):
        if not np.isfinite(e[k]):
            continue
        if previous is not None and e[k] > 0 and e[previous] > 0 and h[k] != h[previous]:
            out[k] = math.log(e[previous] / e[k]) / math.log(h[previous] / h[k])
        previous = k
    return out


# -- the scene of one run -----------------------------------------------------------------------
SCENE_MESH_OPTIONS = ("kind", "seed", "levels", "rule", "fraction", "lloyd_iterations")


def study_scene(
    scene_path, overrides=(), family: str | None = None, options=None, n=None, stabilization: str | None = None
):
    """The scene of one run of a study: the scene file, ``overrides`` ("key.path=value"), then
    the run's stabilization and a ``discretization.mesh`` describing the run's mesh.

    The mesh itself is built by the workflow and passed to the solver; the scene records it. Its
    options outside the scene schema (e.g. ``min_angle``) and a non-integer ``n`` (Delaunay:
    about 2 n² triangles; the scene holds the nearest integer) are kept in the mesh's own meta.
    """
    from vemkit.config.scene import load_scene

    extra = []
    if stabilization is not None:
        extra.append(f"discretization.stabilization={stabilization}")
    if family is not None:
        mesh = {"family": family, "n": max(1, int(round(float(n))))}
        mesh.update({k: v for k, v in (options or {}).items() if k in SCENE_MESH_OPTIONS})
        extra.append("discretization.mesh=" + json.dumps(mesh))
    return load_scene(scene_path, [*overrides, *extra])


# -- error records ------------------------------------------------------------------------------
class CachedProjection:
    """A projection (Pi u_ref) whose values and gradients at the quadrature points are computed once:
    the reference is evaluated at the same points for every coarse run."""

    def __init__(self, projection):
        self._projection = projection
        self._cache = {}

    def __getattr__(self, name):
        return getattr(self._projection, name)

    def _cached(self, key, cells, points, compute):
        hit = self._cache.get(key)
        if hit is None or hit[0] is not cells or hit[1] is not points:
            hit = self._cache[key] = (cells, points, compute(cells, points))
        return hit[2]

    def evaluate(self, cells, points):
        return self._cached("values", cells, points, self._projection.evaluate)

    def gradient_at(self, cells, points):
        return self._cached("gradients", cells, points, self._projection.gradient_at)


class ReferenceSolution:
    """The reference solution (mesh, Pi_1 u_ref) and its quadrature, computed once for many runs.

    ``quadrature`` may be shared between references on the same mesh (the references of the
    different stabilizations).
    """

    def __init__(self, path, quadrature=None, solution=None):
        from vemkit.vem.quadrature import reference_quadrature

        self.path = str(path)
        self.mesh, self.dataset = solution if solution is not None else read_solution(path)
        self.order = solution_order(self.dataset)
        self.projected = CachedProjection(projected_solution_file(self.mesh, self.dataset))
        # exact for the product of two projections of degree k: degree 2k (the degree-2 or degree-5 rule)
        self.quadrature = (
            quadrature if quadrature is not None else reference_quadrature(self.mesh, degree=2 * self.order)
        )
        self.displacement = _displacement(self.dataset)
        self.areas = self.mesh.cell_areas
        self.stabilization = str(self.dataset.attrs.get("stabilization", ""))

    def errors(self, mesh, dataset) -> dict:
        """{"h1", "h1_semi", "l2"} (Pi_1 on each mesh) and "paper" (the paper's measure), SPEC 5.
        Both are k = 1 measures of vertex values: a k = 2 solution or reference is refused."""
        from vemkit.vem.norms import paper_error, projection_error

        refuse_order2(self.dataset, "the convergence study's reference")
        refuse_order2(dataset, "a solution of the convergence study")
        out = projection_error(mesh, _projected(mesh, dataset), self.mesh, self.projected, self.quadrature)
        out["paper"] = paper_error(
            mesh, _displacement(dataset), self.mesh, self.displacement, self.projected, self.areas
        )
        return out


def _displacement(ds) -> np.ndarray:
    return np.stack([ds["u1"].values, ds["u2"].values], axis=1)


def _projected(mesh, ds):
    return projected_solution_file(mesh, ds)


def _same_mesh(a, b) -> bool:
    return (
        a.vertices.shape == b.vertices.shape
        and a.cell_vertices.shape == b.cell_vertices.shape
        and np.array_equal(a.vertices, b.vertices)
        and np.array_equal(a.cell_offsets, b.cell_offsets)
        and np.array_equal(a.cell_vertices, b.cell_vertices)
    )


def run_record(family: str, stabilization: str, n, mesh, ds, reference: ReferenceSolution) -> dict:
    """One error record: the solution ``ds`` on ``mesh`` against ``reference``."""
    err = reference.errors(mesh, ds)
    return {
        "family": str(family),
        "stabilization": str(stabilization),
        "n": n,
        "h": 1.0 / float(n),
        "h_max": float(mesh.h),
        "n_cells": int(mesh.n_cells),
        "n_dofs": int(ds.attrs["n_dofs"]),
        "error_h1": err["h1"],
        "error_h1_semi": err["h1_semi"],
        "error_l2": err["l2"],
        "error_paper": err["paper"],
        "iterations": int(ds.attrs["iterations"]),
        "wall_time": float(ds.attrs.get("wall_time", 0.0)),
        "assembly_time": float(ds.attrs.get("assembly_time", 0.0)),
        "solution_stabilization": str(ds.attrs.get("stabilization", "")),
    }


def family_error_records(family: str, runs, references: dict) -> list[dict]:
    """Error records of one family: ``runs`` = [(stabilization, n, solution_path), ...], each
    against ``references[stabilization]`` (a solution file). Every file is read once, and the
    quadrature is computed once per reference mesh."""
    solutions, refs, quadratures = {}, {}, []

    def solution(path):
        if path not in solutions:
            solutions[path] = read_solution(path)
        return solutions[path]

    def reference(stab):
        if stab not in refs:
            sol = solution(references[stab])
            quad = next((q for m, q in quadratures if _same_mesh(m, sol[0])), None)
            refs[stab] = ReferenceSolution(references[stab], quadrature=quad, solution=sol)
            if quad is None:
                quadratures.append((sol[0], refs[stab].quadrature))
        return refs[stab]

    records = []
    for stab, n, path in runs:
        mesh, ds = solution(path)
        records.append(run_record(family, stab, n, mesh, ds, reference(stab)))
    return records


def error_records(family: str, stabilization: str, runs, reference_path) -> list[dict]:
    """Error records of ``runs`` = [(n, solution_path), ...] against one reference solution file."""
    return family_error_records(family, [(stabilization, n, p) for n, p in runs], {stabilization: reference_path})


def solved_error_records(
    family: str, spec: dict, stabilization: str, meshes, reference_mesh, scene_path, overrides=()
) -> list[dict]:
    """Error records of a variant of the workflow's scene, solved here rather than by the workflow's
    solve rules: the scene with ``overrides`` and ``stabilization`` on every ``meshes`` = [(n, Mesh)]
    of ``family`` (``spec``: its ``build_mesh`` arguments) and on ``reference_mesh`` = (n, Mesh), the
    2^-8 square reference. Table 1 uses it for Gauss quadrature on Gamma_C."""
    from vemkit.studies.scene_solve import solve_scene

    def solve(mesh_spec, n, mesh):
        scene = study_scene(
            scene_path, overrides, mesh_spec["family"], mesh_spec.get("options") or {}, n, stabilization
        )
        require_order1(scene, "the convergence study")
        problem, _, ds = solve_scene(scene, mesh=mesh)
        return problem.mesh, ds

    ref_n, ref_mesh = reference_mesh
    reference = ReferenceSolution("<solved here>", solution=solve({"family": "square"}, ref_n, ref_mesh))
    return [run_record(family, stabilization, n, *solve(spec, n, mesh), reference) for n, mesh in meshes]


def with_paper_variant(ds: xr.Dataset, records, suffix: str, comment: str) -> xr.Dataset:
    """``ds`` with ``error_paper_<suffix>`` and ``order_paper_<suffix>``: the paper's measure of
    ``records`` (a variant of the discretization, e.g. ``gauss``) on the grid of ``ds``; NaN where
    the variant has no run (fill values in the file)."""
    shape = ds["error_h1"].shape
    errors = np.full(shape, np.nan)
    fams, stabs = [str(f) for f in ds["family"].values], [str(s) for s in ds["stabilization"].values]
    ns = [int(n) for n in ds["n"].values]
    for r in records:
        if r["family"] in fams and r["stabilization"] in stabs and int(r["n"]) in ns:
            errors[fams.index(r["family"]), stabs.index(r["stabilization"]), ns.index(int(r["n"]))] = r["error_paper"]
    orders = np.apply_along_axis(lambda e: convergence_orders(ds["h"].values, e), -1, errors)
    dims = ("family", "stabilization", "h")
    return ds.assign(
        {
            f"error_paper_{suffix}": (
                dims,
                errors,
                {
                    "long_name": f"error_paper with {comment}",
                    "units": "1",
                    "comment": "undefined where the variant was not run",
                },
            ),
            f"order_paper_{suffix}": (
                dims,
                orders,
                {"long_name": f"observed order of error_paper_{suffix}", "units": "1"},
            ),
        }
    )


def write_records(records, path) -> Path:
    """Records as JSON (a small intermediate file of the workflow), written atomically."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.part")
    tmp.write_text(json.dumps(list(records), indent=1) + "\n", encoding="utf-8")
    tmp.replace(path)
    return path


def read_records(paths) -> list[dict]:
    out = []
    for p in paths:
        out.extend(json.loads(Path(p).read_text(encoding="utf-8")))
    return out


# -- the dataset ----------------------------------------------------------------------------------
def _checked(records) -> list:
    records = list(records)
    if not records:
        raise ValueError("no error records: nothing to gather")
    for r in records:
        missing = [k for k in ("family", "stabilization", "n", "error_h1", "error_h1_semi") if k not in r]
        if missing:
            raise ValueError(f"error record {r!r} lacks {', '.join(missing)}")
        for key in ("error_h1", "error_h1_semi", "error_paper"):
            if key in r and not (np.isfinite(r[key]) and r[key] >= 0):
                raise ValueError(
                    f"error record {r['family']}/{r['stabilization']}/n{r['n']}: {key} = {r[key]}"
                    " is not a finite non-negative number"
                )
    return records


def _gridded(records, fams, stabs, ns):
    """({variable: (family, stabilization, h) array, NaN where missing}, the mask of existing runs)."""
    shape = (len(fams), len(stabs), len(ns))
    data = {k: np.full(shape, np.nan) for k in _VARIABLES}
    seen = np.zeros(shape, dtype=bool)
    for r in records:
        if r["family"] not in fams or r["stabilization"] not in stabs:
            continue
        idx = (fams.index(r["family"]), stabs.index(r["stabilization"]), ns.index(int(r["n"])))
        if float(r["n"]) != int(r["n"]):
            raise ValueError(f"error record {r['family']}/{r['stabilization']}: n = {r['n']} is not an integer level")
        if seen[idx]:
            raise ValueError(f"two error records for {r['family']}/{r['stabilization']}/n{r['n']}")
        seen[idx] = True
        for k in _VARIABLES:
            if k in r:
                data[k][idx] = float(r[k])
    return data, seen


def _orders(h, errors) -> np.ndarray:
    """convergence_orders of every (family, stabilization) row of a (family, stabilization, h) array."""
    out = np.full(errors.shape, np.nan)
    for i in range(errors.shape[0]):
        for j in range(errors.shape[1]):
            out[i, j] = convergence_orders(h, errors[i, j])
    return out


_UNDEFINED_FIRST = "undefined at the coarsest h (an order needs two levels): _FillValue in the file, NaN in memory"
_ORDERS = {  # order variable: (error variable, long name)
    "order": ("error_h1", "observed convergence order of error_h1: log(e_prev/e) / log(h_prev/h)"),
    "order_h1_semi": ("error_h1_semi", "observed convergence order of error_h1_semi"),
    "order_paper": ("error_paper", "observed convergence order of error_paper (the paper's Table 1 order)"),
}


def _add_variables(ds, data, seen, h, has_paper) -> None:
    dims = ("family", "stabilization", "h")
    for key in ("error_h1", "error_h1_semi", "error_l2", "error_paper", "wall_time", "assembly_time", "h_max"):
        if key != "error_paper" or has_paper:
            long_name, units = RECORD_KEYS[key]
            ds[key] = (dims, data[key], {"long_name": long_name, "units": units})
    for name, (error, long_name) in _ORDERS.items():
        if error != "error_paper" or has_paper:
            ds[name] = (
                dims,
                _orders(h, data[error]),
                {"long_name": long_name, "units": "1", "comment": _UNDEFINED_FIRST},
            )
    for key in ("n_dofs", "n_cells", "iterations"):
        long_name, units = RECORD_KEYS[key]
        values = np.where(np.isnan(data[key]), INT_FILL, data[key]).astype(np.int64)
        ds[key] = (dims, values, {"long_name": long_name, "units": units})
    ds["defined"] = (
        dims,
        seen.astype(np.int8),
        {
            "long_name": "1 where the run exists, 0 where the family has no mesh at this h",
            "flag_values": np.array([0, 1], np.int8),
            "flag_meanings": "missing present",
        },
    )
    ds["order_defined"] = (
        dims,
        np.isfinite(ds["order"].values).astype(np.int8),
        {
            "long_name": "1 where order is defined",
            "flag_values": np.array([0, 1], np.int8),
            "flag_meanings": "undefined defined",
        },
    )


def _provenance(title, scene_yaml, parameters, commit) -> dict:
    versions = package_versions()
    return {
        "title": title,
        "Conventions": "CF-1.8",
        "error_measure": "relative errors of Pi_1 u_h against Pi_1 u_ref in the broken norms over the "
        "reference mesh (SPEC 5); error_h1: full H1 norm, error_h1_semi: H1 seminorm; "
        "error_paper: the paper's own measure |Pi_1^ref(I_ref u_h - u_ref)|_H1 / "
        "|Pi_1^ref u_ref|_H1 (interpolation at the reference vertices, projection on the "
        "reference mesh, H1 seminorm), the one its Table 1 prints",
        "missing_values": "order is undefined at the coarsest h; in the file, a float variable with "
        f"undefined entries has _FillValue = {FLOAT_FILL} there, an integer one {INT_FILL}; "
        "no NaN is stored; see the variables defined and order_defined",
        "scene": scene_yaml,
        "parameters": json.dumps(parameters or {}, sort_keys=True, default=str),
        "package_versions": json.dumps(versions, sort_keys=True),
        "git_commit": commit if commit is not None else git_commit(),
        **{f"version_{name}": version for name, version in versions.items()},
    }


def convergence_dataset(
    records,
    *,
    scene_yaml: str = "",
    parameters=None,
    families=None,
    stabilizations=None,
    title: str = "vemkit convergence study",
    commit: str | None = None,
) -> xr.Dataset:
    """The convergence Dataset (dims ``family``, ``stabilization``, ``h``) of error records.

    ``families`` / ``stabilizations`` fix the order of the labels (default: first appearance).
    ``h`` runs from coarse to fine, as in the paper's Table 1. See the module docstring for how
    undefined entries are marked.
    """
    records = _checked(records)
    fams = list(families) if families is not None else list(dict.fromkeys(r["family"] for r in records))
    stabs = (
        list(stabilizations) if stabilizations is not None else list(dict.fromkeys(r["stabilization"] for r in records))
    )
    ns = sorted({int(r["n"]) for r in records})
    data, seen = _gridded(records, fams, stabs, ns)
    h = 1.0 / np.asarray(ns, dtype=float)  # n increasing: h runs from coarse to fine
    ds = xr.Dataset(
        coords={
            "family": ("family", np.array(fams, dtype=str), {"long_name": "mesh family label"}),
            "stabilization": (
                "stabilization",
                np.array(stabs, dtype=str),
                {"long_name": "stabilization alpha_K of the dofi-dofi form (SPEC 3)"},
            ),
            "h": ("h", h, {"long_name": "nominal mesh size h = 1/n", "units": "mm"}),
            "n": ("h", np.asarray(ns, dtype=np.int64), {"long_name": "cells per side n = 1/h"}),
        }
    )
    _add_variables(ds, data, seen, h, has_paper=any("error_paper" in r for r in records))
    ds.attrs.update(_provenance(title, scene_yaml, parameters, commit))
    return ds


def write_convergence(ds: xr.Dataset, path):
    """Write atomically; undefined entries as declared fill values (``vemkit.io.fill_values``)."""
    return write_with_fill_values(ds, path)


def read_convergence(path) -> xr.Dataset:
    """Read a file written by :func:`write_convergence`: float fill values back to NaN, integer ones kept as -1."""
    return read_with_fill_values(path)


def square_rows(ds: xr.Dataset, family: str = "square") -> xr.Dataset:
    """The Table 1 part of a convergence Dataset: one family, h where it has runs."""
    sub = ds.sel(family=[family])
    keep = sub["defined"].values.astype(bool).any(axis=(0, 1))
    return sub.isel(h=np.flatnonzero(keep))
