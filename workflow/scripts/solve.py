"""Rules solve and solve_levels: the configured scene, one stabilization, on each mesh file."""

from _helpers import level, logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    import json

    import numba

    numba.set_num_threads(max(1, min(smk.threads, numba.config.NUMBA_NUM_THREADS)))

    from vemkit.studies.convergence import study_scene
    from vemkit.mesh.files import read_ugrid
    from vemkit.io.solution_file import write_netcdf
    from vemkit.studies.scene_solve import solve_scene

    spec, stab, label = smk.params.spec, smk.wildcards.stab, smk.wildcards.label
    for n, mesh_path, path in zip(smk.params.levels, smk.input.meshes, smk.output, strict=True):
        n = level(n)
        scene = study_scene(smk.params.scene, smk.params.overrides, spec["family"], spec.get("options") or {}, n, stab)
        problem, solution, ds = solve_scene(scene, mesh=read_ugrid(mesh_path))
        ds.attrs["workflow_run"] = json.dumps({"family": label, "n": n, "stabilization": stab, "mesh_file": mesh_path})
        write_netcdf(ds, path)
        print(f"{path}: {problem.n_dofs} dofs, {solution.method} {solution.iterations} iterations, "
              f"solver {solution.wall_time:.3f} s, assembly {problem.info.get('assembly_time', 0.0):.3f} s", flush=True)
