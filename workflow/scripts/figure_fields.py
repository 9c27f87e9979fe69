"""Rule figure_fields: u1 and u2 on one mesh (the paper's Figs. 3-5)."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.io.solution_file import read_solution
    from vemkit.report import figures as plots

    mesh, ds = read_solution(smk.input[0])
    spec = smk.params.spec
    title = f"{smk.wildcards.fig}: {spec['mesh']} mesh, {mesh.n_cells} cells ({ds.attrs['stabilization']})"
    fig = plots.displacement_figure(mesh, ds["u1"].values, ds["u2"].values, title=title)
    plots.save(fig, smk.output.png, smk.output.pdf)
