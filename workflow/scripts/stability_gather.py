"""Rule stability: gather the parts of the robustness matrix (netCDF, Markdown report, plot)."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    import xarray as xr

    from vemkit.report.figures import save
    from vemkit.report.study_figures import stability_figure
    from vemkit.studies import robustness
    from vemkit.studies.sweeps import read_dataset, write_dataset

    parts = [read_dataset(p) for p in smk.input]
    ds = (
        xr.concat(parts, dim="case", data_vars="minimal", coords="minimal", compat="override", combine_attrs="override")
        if len(parts) > 1
        else parts[0]
    )
    cases = robustness.select_cases(None if smk.params.settings["cases"] == "all" else smk.params.settings["cases"])
    ds = robustness.summarize(ds.sel(case=[c["name"] for c in cases]))  # the parts interleave the cases
    write_dataset(ds, smk.output.nc)
    text = robustness.stability_markdown(ds)
    with open(smk.output.md, "w", encoding="utf-8") as stream:
        stream.write(text)
    save(stability_figure(ds), smk.output.png)
    print(text)
