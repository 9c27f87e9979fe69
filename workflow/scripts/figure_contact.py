"""Rule figure_contact: pressure, tangential stress, slip and zones along Gamma_C."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.io.solution_file import read_solution
    from vemkit.report import figures as plots

    _, ds = read_solution(smk.input[0])
    spec = smk.params.spec
    title = rf"contact boundary $\Gamma_C$: {spec['mesh']} mesh, n = {spec['n']} ({ds.attrs['stabilization']})"
    fig = plots.contact_figure(ds, title=title)
    plots.save(fig, smk.output.png, smk.output.pdf)
