"""Rule three_d_convergence: the manufactured records of every case into one Dataset (case x level:
errors, observed orders in h = 1/n and per DOF) and a Markdown table."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    import json

    from vemkit.studies.three_d import convergence_dataset, markdown_table

    COLUMNS = ("n", "cells", "dofs", "error_h1", "rate_h1", "rate_h1_dofs", "error_l2", "rate_l2", "rate_l2_dofs")
    cases = list(smk.params.cases)
    records = []
    for path in smk.input:
        for r in json.load(open(path, encoding="utf-8")):
            r["family"] = r.pop("case")  # the case label is the dataset's family coordinate
            records.append(r)
    ds = convergence_dataset(
        records,
        cases,
        attrs={
            "title": "3D manufactured convergence (vemkit.studies.three_d, config/three_d.yaml)",
            "scenes": json.dumps({c: smk.params.manufactured[c]["scene"] for c in cases}),
            "errors": "relative errors of Pi u_h against the exact u: error_h1 full H1 norm, error_l2 L2 norm",
        },
    )
    ds.to_netcdf(smk.output.nc)
    rows = []
    for i, case in enumerate(cases):
        for j in range(ds.sizes["level"]):
            if ds["n"].values[i, j] == ds["n"].values[i, j]:
                rows.append(
                    {
                        "case": case,
                        **{k: float(ds[k].values[i, j]) for k in COLUMNS},
                    }
                )
    for r in rows:
        r["n"], r["cells"], r["dofs"] = int(r["n"]), int(r["cells"]), int(r["dofs"])
    summary = [
        {"case": c, "order_h1": float(ds["order_h1"].values[i]), "order_l2": float(ds["order_l2"].values[i])}
        for i, c in enumerate(cases)
    ]
    text = (
        "# 3D manufactured convergence\n\nRelative errors of Pi u_h against the exact u "
        "(elasticity: config/scenes/3d/box_manufactured.yaml, extruded_manufactured.yaml; the cases "
        "contact-<kind>-<family>: the manufactured frictional contact of config/scenes/3d/contact_<kind>"
        "[_extruded].yaml, tests/manufactured_contact3d.py); rates in h = 1/n and, per DOF, in dofs^(-1/3).\n\n"
        + markdown_table(
            rows,
            ["case", *COLUMNS],
            formats={k: ".2f" for k in ("rate_h1", "rate_l2", "rate_h1_dofs", "rate_l2_dofs")},
        )
        + "\nOrders between the two finest levels, in the mean cell size (cells^(-1/3)):\n\n"
        + markdown_table(summary, ["case", "order_h1", "order_l2"], formats={"order_h1": ".2f", "order_l2": ".2f"})
    )
    open(smk.output.md, "w", encoding="utf-8").write(text)
    print(text)
