"""Error records of convergence studies: one coarse solve against the reference solution (docs/reference/mathematics.md).

A *record* is a dict with the keys of :data:`RECORD_KEYS`: :func:`error_records` and
:func:`family_error_records` compute them from solution files, :func:`solved_error_records` solves
the runs itself (a variant of the workflow's scene), :func:`write_records` / :func:`read_records`
keep them as the workflow's small JSON intermediates. ``vemkit.studies.convergence`` gathers them
into the study's Dataset.

Imports: vemkit.config, vemkit.io, vemkit.vem, vemkit.studies.solution_order and scene_solve.
"""

from __future__ import annotations

import json
import secrets
from pathlib import Path

import numpy as np

from vemkit.io.solution_file import read_solution
from vemkit.io.temporary_names import temporary_name
from vemkit.studies.solution_order import projected_solution_file, refuse_order2, require_order1, solution_order

#: keys of one error record, with their meaning and units
RECORD_KEYS = {
    "family": ("mesh family label (config meshes)", None),
    "stabilization": ("stabilization of the VEM bilinear form (and of the reference)", None),
    "n": ("cells per side, n = 1/h", "1"),
    "h": ("nominal mesh size 1/n", "mm"),
    "h_max": ("largest cell diameter of the mesh", "mm"),
    "n_cells": ("number of cells", "1"),
    "n_dofs": ("number of free displacement unknowns", "1"),
    "error_h1": ("||Pi_1(u_h - u_ref)||_H1 / ||Pi_1 u_ref||_H1 (full H1 norm, broken)", "1"),
    "error_h1_semi": ("|Pi_1(u_h - u_ref)|_H1 / |Pi_1 u_ref|_H1 (H1 seminorm, broken)", "1"),
    "error_l2": ("||Pi_1(u_h - u_ref)||_L2 / ||Pi_1 u_ref||_L2", "1"),
    "error_paper": (
        "|Pi_1^ref(I_ref u_h - u_ref)|_H1 / |Pi_1^ref u_ref|_H1: the paper's measure, I_ref the "
        "interpolant at the reference vertices (bilinear on squares, Wachspress / mean value "
        "coordinates elsewhere), H1 seminorm broken over the reference cells (docs/reference/mathematics.md)",
        "1",
    ),
    "iterations": ("nonlinear contact solver iterations", "1"),
    "wall_time": ("contact solver wall time (with the linear solver set-up)", "s"),
    "assembly_time": ("assembly wall time of the discrete problem", "s"),
}


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
        """{"h1", "h1_semi", "l2"} (Pi_1 on each mesh) and "paper" (the paper's measure), docs/reference/mathematics.md.
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


def write_records(records, path) -> Path:
    """Records as JSON (a small intermediate file of the workflow), written atomically."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(temporary_name(path.name, secrets.token_hex(6)))  # fits NAME_MAX for any name
    tmp.write_text(json.dumps(list(records), indent=1) + "\n", encoding="utf-8")
    tmp.replace(path)
    return path


def read_records(paths) -> list[dict]:
    out = []
    for p in paths:
        out.extend(json.loads(Path(p).read_text(encoding="utf-8")))
    return out
