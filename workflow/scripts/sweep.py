"""Rules sweep_part (solve one part of a grid), sweep (gather the parts) and sweep_figure."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.studies import sweeps

    if smk.rule == "sweep_part":
        from vemkit.config.scene import load_scene

        s = smk.params.settings
        part = int(smk.wildcards.part)
        grid = sweeps.split_grid(s["grid"], s["parts"])[part]
        scene = load_scene(s["scene"], s["overrides"])

        def progress(index, values, point):
            o = point.outcome
            print(f"{values}: {o.status} {o.iterations} it {o.wall_time:.3f} s {o.message}", flush=True)

        ds = sweeps.run_sweep(scene, grid, time_budget=s["time_budget"], check_tol=s["check_tol"], progress=progress,
                              attrs={"sweep": smk.wildcards.sweep, "part": part, "workflow_settings": repr(s)})
        sweeps.write_dataset(ds, smk.output[0])
        print(f"{smk.output[0]}: {ds.attrs['converged_points']}/{ds.attrs['points']} converged, "
              f"{ds.attrs['total_time']:.2f} s, reuse {ds.attrs['reuse']}")
    elif smk.rule == "sweep":
        ds = sweeps.combine_parts([sweeps.read_dataset(p) for p in smk.input])
        ds.attrs.pop("part", None)
        sweeps.write_dataset(ds, smk.output[0])
        print(f"{smk.output[0]}: {ds.attrs['converged_points']}/{ds.attrs['points']} converged, "
              f"solve time of the parts {ds.attrs['total_time']:.2f} s")
    else:  # sweep_figure
        from vemkit.report import study_figures as sweep_plots
        from vemkit.report.figures import save

        ds = sweeps.read_dataset(smk.input[0])
        spec, kind, name = dict(smk.params.figure), smk.wildcards.kind, smk.wildcards.sweep
        if kind == "map":
            fig = sweep_plots.sweep_map_figure(ds, spec["x"], spec["y"], spec["quantities"], spec.get("select"), name)
        elif kind == "lines":
            fig = sweep_plots.sweep_lines_figure(ds, spec["x"], spec.get("hue"), spec["quantities"], spec.get("select"), name)
        else:
            fig = sweep_plots.sweep_profiles_figure(ds, spec["across"], spec.get("select"), name)
        save(fig, smk.output[0])
