"""Rule adaptivity_summary: rates, DOFs and wall time at equal error, effectivity, for every scene."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    import xarray as xr

    from vemkit.studies.adaptivity_compare import compare, history, summary_json, summary_markdown

    comparisons = {}
    cases = zip(smk.params.scenes, smk.params.errors, smk.input.adaptive, smk.input.uniform, strict=True)
    for scene, error, adaptive, uniform in cases:
        with xr.open_dataset(adaptive) as a, xr.open_dataset(uniform) as u:
            comparisons[scene] = compare(history(a), history(u), error, smk.params.targets)
    text = summary_markdown(comparisons)
    with open(smk.output.md, "w", encoding="utf-8") as stream:
        stream.write(text)
    with open(smk.output.json, "w", encoding="utf-8") as stream:
        stream.write(summary_json(comparisons))
    print(text)
