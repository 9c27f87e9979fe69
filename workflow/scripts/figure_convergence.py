"""Rule figure_convergence: the log-log convergence plot of every family, with a slope-1 guide."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.report import figures as plots
    from vemkit.studies.convergence import read_convergence

    fig = plots.convergence_figure(read_convergence(smk.input[0]), norm=smk.params.norm)
    plots.save(fig, smk.output.png, smk.output.pdf)
