"""Shared by the workflow scripts: the job's log file, the level n of a wildcard, and the bodies of
the rules that come in a one-level and a batched (all levels in one job) form."""

from __future__ import annotations

import contextlib
import sys
import time
import traceback


@contextlib.contextmanager
def logged(smk):
    """Send the job's prints and any traceback to its log file (``log:`` of the rule)."""
    path = smk.log[0] if smk.log else None
    stream = open(path, "w", encoding="utf-8") if path else sys.stderr  # noqa: SIM115
    t0 = time.perf_counter()
    try:
        with contextlib.redirect_stdout(stream), contextlib.redirect_stderr(stream):
            print(f"rule {smk.rule}: wildcards {dict(smk.wildcards)}", flush=True)
            try:
                yield
            except BaseException:
                traceback.print_exc()
                raise
            finally:
                print(f"elapsed {time.perf_counter() - t0:.3f} s", flush=True)
    finally:
        if path:
            stream.close()


def level(text):
    """The n of a file name as a number: 16 -> 16, 22.627417 -> 22.627417."""
    value = float(text)
    return int(value) if value.is_integer() else value


def write_meshes(smk):
    """Rules mesh and mesh_levels: the meshes of one family (one per level) as UGRID netCDF."""
    from vemkit.mesh.checks import validate_mesh
    from vemkit.mesh.families import build_mesh
    from vemkit.mesh.ugrid import write_ugrid

    spec = smk.params.spec
    for n, path in zip(smk.params.levels, smk.output, strict=True):
        mesh = build_mesh(spec["family"], level(n), **dict(spec.get("options") or {}))
        validate_mesh(mesh)
        write_ugrid(mesh, path)
        print(f"{path}: {mesh.n_cells} cells, {mesh.n_vertices} vertices, h = {mesh.h:.4g}, meta {mesh.meta}")


def write_solutions(smk):
    """Rules solve and solve_levels: the configured scene, one stabilization, on each mesh file."""
    import json

    import numba

    from vemkit.io.solution_file import write_netcdf
    from vemkit.mesh.files import read_ugrid
    from vemkit.studies.error_records import study_scene
    from vemkit.studies.scene_solve import solve_scene

    numba.set_num_threads(max(1, min(smk.threads, numba.config.NUMBA_NUM_THREADS)))
    spec, stab, label = smk.params.spec, smk.wildcards.stab, smk.wildcards.label
    for n, mesh_path, path in zip(smk.params.levels, smk.input.meshes, smk.output, strict=True):
        n = level(n)
        scene = study_scene(smk.params.scene, smk.params.overrides, spec["family"], spec.get("options") or {}, n, stab)
        problem, solution, ds = solve_scene(scene, mesh=read_ugrid(mesh_path))
        ds.attrs["workflow_run"] = json.dumps({"family": label, "n": n, "stabilization": stab, "mesh_file": mesh_path})
        write_netcdf(ds, path)
        print(
            f"{path}: {problem.n_dofs} dofs, {solution.method} {solution.iterations} iterations, "
            f"solver {solution.wall_time:.3f} s, assembly {problem.info.get('assembly_time', 0.0):.3f} s",
            flush=True,
        )


def write_convergence_file(smk):
    """Rules table1_dataset and convergence_dataset: error records -> one convergence netCDF (with
    error_paper_gauss when the Gauss-quadrature records of table1.gauss are given)."""
    from vemkit.studies.convergence import convergence_dataset, with_paper_variant, write_convergence
    from vemkit.studies.error_records import read_records, study_scene

    p = smk.params
    scene = study_scene(
        p.scene, p.parameters["overrides"] + [f"solver.{k}={v}" for k, v in p.parameters["solver"].items()]
    )
    ds = convergence_dataset(
        read_records(smk.input.errors),
        scene_yaml=scene.to_yaml(),
        parameters=p.parameters,
        families=p.families,
        stabilizations=p.stabilizations,
        title=p.title,
    )
    if smk.input.gauss:
        ds = with_paper_variant(
            ds,
            read_records(smk.input.gauss),
            "gauss",
            f"contact_quadrature: gauss, {p.gauss['points']} Gauss points per Gamma_C edge",
        )
    ds.attrs["scene_comment"] = (
        "the scene file with the workflow's solver settings and overrides; every run "
        "replaces discretization.mesh and discretization.stabilization (see parameters)"
    )
    write_convergence(ds, smk.output[0])
    print(ds)
