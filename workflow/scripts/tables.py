"""Rule table: a convergence netCDF -> Markdown, CSV and LaTeX tables."""

from pathlib import Path

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.report import tables
    from vemkit.studies.convergence import read_convergence

    ds = read_convergence(smk.input[0])
    kind = smk.wildcards.table
    for fmt in ("md", "csv", "tex"):
        writer = {"md": "markdown", "csv": "csv", "tex": "latex"}[fmt]
        text = getattr(tables, f"{kind}_{writer}")(ds)
        Path(smk.output[fmt]).write_text(text, encoding="utf-8")
    print(Path(smk.output.md).read_text(encoding="utf-8"))
