"""Rule mesh_levels: every convergence level of a family in one job."""

from _helpers import logged, write_meshes

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    write_meshes(smk)
