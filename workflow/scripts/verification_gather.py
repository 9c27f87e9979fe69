"""Rule verification_gather: the records of every (scene, family) into one verification netCDF file."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.studies.error_records import read_records
    from vemkit.studies.verification import verification_dataset, write_verification

    ds = verification_dataset(read_records(smk.input), scenes=smk.params.scenes, families=smk.params.families)
    write_verification(ds, smk.output[0])
    print(ds)
