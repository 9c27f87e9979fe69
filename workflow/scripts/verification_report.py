"""Rule verification_report: the Markdown tables and one figure per scene."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.io.output_files import atomic_outputs
    from vemkit.io.solution_file import read_solution
    from vemkit.report.figures import save
    from vemkit.report.verification import scene_figure, verification_markdown
    from vemkit.studies.verification import read_verification

    ds = read_verification(smk.input.dataset)
    text = verification_markdown(ds)
    with atomic_outputs(smk.output.md) as (temporary,):
        temporary.write_text(text, encoding="utf-8")
    print(text)
    for scene, solution, figure in zip(smk.params.scenes, smk.input.solutions, smk.output.figures, strict=True):
        mesh, solved = read_solution(solution)
        run = ds.sel(scene=scene, family=smk.params.family, level=smk.params.level)
        hertz = (float(run["half_width_hertz"]), float(run["peak_pressure_hertz"])) if scene == "hertz" else None
        save(scene_figure(scene, mesh, solved, hertz=hertz), figure)
        print(f"{figure}: {mesh.n_cells} cells", flush=True)
