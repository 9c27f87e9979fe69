"""Rules mesh and mesh_levels: build the meshes of one family (one per level) as UGRID netCDF."""

from _helpers import level, logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.mesh.families import build_mesh
    from vemkit.mesh.checks import validate_mesh
    from vemkit.mesh.files import write_ugrid

    spec = smk.params.spec
    for n, path in zip(smk.params.levels, smk.output, strict=True):
        mesh = build_mesh(spec["family"], level(n), **dict(spec.get("options") or {}))
        validate_mesh(mesh)
        write_ugrid(mesh, path)
        print(f"{path}: {mesh.n_cells} cells, {mesh.n_vertices} vertices, h = {mesh.h:.4g}, meta {mesh.meta}")
