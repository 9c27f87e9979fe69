"""Rule adaptivity_reference: the reference solution of one scene of config/adaptivity.yaml
(vemkit.studies.adaptivity_compare.reference_dataset: {uniform: L} or {adaptive: N})."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.config.scene import load_scene
    from vemkit.io.solution_file import write_netcdf
    from vemkit.studies.adaptivity_compare import reference_dataset

    case = smk.params.case
    scene = load_scene(case["scene"], case["overrides"])
    ds = reference_dataset(
        scene,
        case["reference"],
        case["theta"],
        progress=lambda step, r: print(
            f"step {step + 1}: {r['n_dofs']} dofs, estimate {r['estimate']:.3e}, {r['wall_time']:.1f} s", flush=True
        ),
    )
    print(
        f"{ds.attrs['reference_kind']}: {ds.attrs['n_dofs']} dofs, {ds.attrs['solver']} {ds.attrs['iterations']} "
        f"iterations, {ds.attrs['wall_time']:.1f} s",
        flush=True,
    )
    write_netcdf(ds, smk.output[0])
