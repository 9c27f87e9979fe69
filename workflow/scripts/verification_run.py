"""Rule verification_run: one shipped scene on one mesh family at every mesh size of its case."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.io.solution_file import write_netcdf
    from vemkit.studies.error_records import write_records
    from vemkit.studies.verification import CASES, run_case

    scene, family = smk.wildcards.scene, smk.wildcards.family
    figure_h = CASES[scene].sizes[smk.params.figure_level]

    def keep(h, problem, ds):
        print(
            f"{scene} {family} h = {h:g}: {problem.n_dofs} unknowns, {ds.attrs['solver']} "
            f"{ds.attrs['iterations']} iterations, {ds.attrs['wall_time']:.3f} s",
            flush=True,
        )
        if h == figure_h:
            write_netcdf(ds, smk.output.solution)

    records = run_case(scene, smk.input.scene, family, on_solution=keep)
    for record in records:
        print(record, flush=True)
    write_records(records, smk.output.records)
