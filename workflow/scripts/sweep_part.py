"""Rule sweep_part: solve one part of a sweep's grid."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.config.scene import load_scene
    from vemkit.studies import sweeps

    s = smk.params.settings
    part = int(smk.wildcards.part)
    grid = sweeps.split_grid(s["grid"], s["parts"])[part]
    scene = load_scene(s["scene"], s["overrides"])

    def progress(index, values, point):
        o = point.outcome
        print(f"{values}: {o.status} {o.iterations} it {o.wall_time:.3f} s {o.message}", flush=True)

    ds = sweeps.run_sweep(
        scene,
        grid,
        time_budget=s["time_budget"],
        check_tol=s["check_tol"],
        progress=progress,
        attrs={"sweep": smk.wildcards.sweep, "part": part, "workflow_settings": repr(s)},
    )
    sweeps.write_dataset(ds, smk.output[0])
    print(
        f"{smk.output[0]}: {ds.attrs['converged_points']}/{ds.attrs['points']} converged, "
        f"{ds.attrs['total_time']:.2f} s, reuse {ds.attrs['reuse']}"
    )
