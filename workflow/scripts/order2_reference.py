"""Rule order2_reference: the k = 2 reference of the Section 4 study (the paper's scene, fine squares)."""

import json

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    import numba

    from vemkit.io.solution_file import write_netcdf
    from vemkit.mesh.families import build_mesh
    from vemkit.studies.error_records import study_scene
    from vemkit.studies.scene_solve import solve_scene

    numba.set_num_threads(max(1, min(smk.threads, numba.config.NUMBA_NUM_THREADS)))
    s = smk.params.settings
    ref = s["reference"]
    scene = study_scene(s["scene"], s["overrides"] + ["discretization.order=2"], ref["family"], {}, ref["n"])
    problem, solution, ds = solve_scene(scene, mesh=build_mesh(ref["family"], ref["n"]), verify=True)
    ds.attrs["workflow_run"] = json.dumps({"case": "reference", "n": ref["n"], "order": 2})
    write_netcdf(ds, smk.output[0])
    print(
        f"{smk.output[0]}: {ds.attrs['n_space_dofs']} dofs ({problem.n_dofs} unknowns), {solution.method} "
        f"{solution.iterations} iterations, {solution.wall_time:.3f} s",
        flush=True,
    )
