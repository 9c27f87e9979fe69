"""Rules order2_solve and order2_manufactured_solve: a scene (the paper's, or a manufactured contact
solution) with order k on one mesh of one case of the Section 4 study."""

import json

from _helpers import level, logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.io.solution_file import write_netcdf
    from vemkit.mesh.families import build_mesh
    from vemkit.studies.error_records import study_scene
    from vemkit.studies.scene_solve import solve_scene

    s = smk.params.settings
    case = s["cases"][smk.wildcards.case]
    n, options = level(smk.wildcards.n), dict(case.get("options") or {})
    scene = study_scene(
        s["scene"],
        s["overrides"] + [f"discretization.order={case['order']}"] + list(case.get("overrides", [])),
        case["family"],
        options,
        n,
    )
    problem, solution, ds = solve_scene(scene, mesh=build_mesh(case["family"], n, **options), verify=True)
    ds.attrs["workflow_run"] = json.dumps(
        {"study": s.get("study", "paper"), "case": smk.wildcards.case, "n": n, "order": case["order"]}
    )
    write_netcdf(ds, smk.output[0])
    print(
        f"{smk.output[0]}: k = {case['order']}, {ds.attrs.get('n_space_dofs', problem.n_dofs)} dofs "
        f"({problem.n_dofs} unknowns), {solution.method} {solution.iterations} iterations, "
        f"{solution.wall_time:.3f} s",
        flush=True,
    )
