"""Rule figure_deformed: the deformed mesh, grey = shear energy density (the paper's Fig. 6)."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.io.solution_file import read_solution
    from vemkit.report import figures as plots

    mesh, ds = read_solution(smk.input[0])
    spec = smk.params.spec
    fig = plots.deformed_figure(mesh, ds, magnification=spec.get("magnification"))
    plots.save(fig, smk.output.png, smk.output.pdf)
    pen = ds["penetration"].values
    x = ds["contact_x"].values[pen > 0]
    print(f"penetration on x in [{x.min():.4f}, {x.max():.4f}], max {pen.max():.4g} mm" if x.size else "no penetration")
