"""Rule errors: every level and stabilization of one family against the reference (docs/reference/mathematics.md): the
three measures (the paper's, and Pi_1 on each mesh in the full H1 norm and the H1 seminorm)."""

from _helpers import level, logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.studies.error_records import family_error_records, write_records

    runs = [(stab, level(n), path) for stab, n, path in smk.params.runs]
    records = family_error_records(smk.wildcards.label, runs, smk.params.references)
    write_records(records, smk.output[0])
    for r in records:
        print(
            f"{r['stabilization']:>9} n={r['n']:<3}: paper {r['error_paper']:.6e}  H1 {r['error_h1']:.6e}  "
            f"H1-semi {r['error_h1_semi']:.6e}  L2 {r['error_l2']:.6e}"
        )
