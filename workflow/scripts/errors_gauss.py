"""Rule errors_gauss: Table 1's family and the reference solved with Gauss quadrature on Gamma_C
(config table1.gauss), and measured like rule errors (docs/reference/mathematics.md)."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.mesh.files import read_ugrid
    from vemkit.studies.error_records import solved_error_records, write_records

    p = smk.params
    meshes = [(n, read_ugrid(path)) for n, path in zip(p.levels, smk.input.meshes, strict=True)]
    records = solved_error_records(
        smk.wildcards.label,
        p.spec,
        p.stabilization,
        meshes,
        (p.reference_n, read_ugrid(smk.input.reference)),
        p.scene,
        p.overrides,
    )
    write_records(records, smk.output[0])
    for r in records:
        print(
            f"{r['stabilization']:>9} n={r['n']:<3}: paper {r['error_paper']:.6e}  H1 {r['error_h1']:.6e}  "
            f"({r['iterations']} iterations)"
        )
