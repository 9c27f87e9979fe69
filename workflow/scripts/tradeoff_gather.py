"""Rule tradeoff: gather every family's runs; Pareto fronts, the Markdown answer and the plot."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    import json

    from vemkit.config.scene import load_scene
    from vemkit.report.figures import save
    from vemkit.report.study_figures import pareto_figure
    from vemkit.studies import tradeoff_answers
    from vemkit.studies.error_records import read_records
    from vemkit.studies.sweeps import write_dataset

    s = smk.params.settings
    scene = load_scene(s["scene"], s["overrides"])
    ds = tradeoff_answers.tradeoff_dataset(
        read_records(smk.input),
        targets=s["targets"],
        gains=s["refinement_gain"],
        scene_yaml=scene.to_yaml(),
        settings=s,
    )
    write_dataset(ds, smk.output.nc)
    text = tradeoff_answers.tradeoff_markdown(ds)
    with open(smk.output.md, "w", encoding="utf-8") as stream:
        stream.write(text)
    save(pareto_figure(ds, ds.attrs["error"], s["targets"]), smk.output.png)
    print(text)
    print(json.dumps(json.loads(ds.attrs["refinement_gain"]), indent=1))
