"""Rule mesh: one mesh of a family as UGRID netCDF."""

from _helpers import logged, write_meshes

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    write_meshes(smk)
