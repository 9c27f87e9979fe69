"""Rules stability_part (run a share of the cases) and stability (gather: netCDF, Markdown, plot)."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.studies import robustness as stability
    from vemkit.studies.sweeps import read_dataset, write_dataset

    s = smk.params.settings
    if smk.rule == "stability_part":
        import numpy as np

        from vemkit.config.scene import load_scene

        cases = stability.select_cases(None if s["cases"] == "all" else s["cases"])
        part = int(smk.wildcards.part)
        mine = [cases[i] for i in np.array_split(np.arange(len(cases)), s["parts"])[part]]
        scene = load_scene(s["scene"], s["overrides"])

        def progress(result):
            for method, o in result["outcomes"].items():
                print(f"{result['case']['name']:<40} {method:<6} {o.status:<22} {o.iterations:>5} it "
                      f"{o.wall_time:7.3f} s  {o.message}", flush=True)

        results = stability.run_matrix(scene, mine, s["solvers"], s["n"], time_budget=s["time_budget"],
                                       check_tol=s["check_tol"], progress=progress)
        ds = stability.stability_dataset(results, scene_yaml=scene.to_yaml(), settings=s)
        write_dataset(ds, smk.output[0])
    else:
        import xarray as xr

        from vemkit.report.figures import save
        from vemkit.report.study_figures import stability_figure

        parts = [read_dataset(p) for p in smk.input]
        ds = xr.concat(parts, dim="case", data_vars="minimal", coords="minimal", compat="override",
                       combine_attrs="override") if len(parts) > 1 else parts[0]
        ds = stability.summarize(ds)
        write_dataset(ds, smk.output.nc)
        text = stability.stability_markdown(ds)
        with open(smk.output.md, "w", encoding="utf-8") as stream:
            stream.write(text)
        save(stability_figure(ds), smk.output.png)
        print(text)
