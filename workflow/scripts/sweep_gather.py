"""Rule sweep: gather the parts of a sweep into one file."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.studies import sweeps

    ds = sweeps.combine_parts([sweeps.read_dataset(p) for p in smk.input])
    ds.attrs.pop("part", None)
    sweeps.write_dataset(ds, smk.output[0])
    print(
        f"{smk.output[0]}: {ds.attrs['converged_points']}/{ds.attrs['points']} converged, "
        f"solve time of the parts {ds.attrs['total_time']:.2f} s"
    )
