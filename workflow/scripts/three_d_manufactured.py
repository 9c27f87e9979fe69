"""Rule three_d_manufactured: one manufactured case (scene with exact:, family) at every level; the
solution at figure_level as a mesh3d file and as VTU polyhedra."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    import json

    from vemkit.io.solution_file import write_netcdf
    from vemkit.studies.three_d import load_scene_data, manufactured_run, with_solver, write_solution_vtu

    case = smk.params.case
    data = with_solver(load_scene_data(smk.input.scene), smk.params.solver)
    levels = list(case["levels"])
    keep = levels[smk.params.figure_level]
    records = []
    for n in levels:
        record, problem, ds = manufactured_run(data, case["family"], n, case.get("options"))
        record["case"] = smk.wildcards.case
        records.append(record)
        print(record, flush=True)
        if n == keep:
            write_netcdf(ds, smk.output.solution)
            write_solution_vtu(problem.mesh, ds, smk.output.vtu)
    with open(smk.output.records, "w", encoding="utf-8") as f:
        json.dump(records, f, indent=1)
