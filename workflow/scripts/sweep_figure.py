"""Rule sweep_figure: a map, lines or contact profiles of a sweep."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.report import study_figures
    from vemkit.report.figures import save
    from vemkit.studies import sweeps

    ds = sweeps.read_dataset(smk.input[0])
    spec, kind, name = dict(smk.params.figure), smk.wildcards.kind, smk.wildcards.sweep
    if kind == "map":
        fig = study_figures.sweep_map_figure(ds, spec["x"], spec["y"], spec["quantities"], spec.get("select"), name)
    elif kind == "lines":
        fig = study_figures.sweep_lines_figure(
            ds, spec["x"], spec.get("hue"), spec["quantities"], spec.get("select"), name
        )
    else:
        fig = study_figures.sweep_profiles_figure(ds, spec["across"], spec.get("select"), name)
    save(fig, smk.output[0])
