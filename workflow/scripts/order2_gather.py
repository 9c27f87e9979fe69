"""Rule order2_gather: every run of the Section 4 study in one netCDF file, the observed orders and
the Markdown table.

Orders are per degree of freedom, p = -2 dlog(error) / dlog(DOFs) between consecutive levels of a
case: on uniform meshes (DOFs ~ h^-2) it is the order in h; on meshes refined at Gamma_C it says what
the refinement buys per DOF. k = 2 counts every degree of freedom of the space (vertex values, edge
and cell means; the cell means are condensed out of the solve: n_unknowns).
"""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
ERRORS = ("error_h1", "error_h1_semi", "error_l2", "error_contact_l2", "error_paper")
LABELS = {"error_h1": "H1", "error_h1_semi": "H1 semi", "error_l2": "L2", "error_contact_l2": "L2(Gamma_C)",
          "error_paper": "paper's measure"}


def dataset(records, settings, boundary):
    import numpy as np
    import xarray as xr

    from vemkit.io.provenance import git_commit, package_versions

    run = "run"
    ds = xr.Dataset(coords={"case": (run, [r["case"] for r in records]), "n": (run, [r["n"] for r in records])})
    for key in [k for k in records[0] if k not in ("case", "n", "family")]:
        ds[key] = (run, np.array([r.get(key, np.nan) for r in records], dtype=float if "error" in key or
                                 "share" in key or key == "wall_time" else np.int64))
    ds["family"] = (run, [r["family"] for r in records])
    for key in ERRORS:
        order = np.full(len(records), np.nan)
        for i in range(1, len(records)):
            if records[i]["case"] == records[i - 1]["case"]:
                order[i] = -2 * np.log(records[i][key] / records[i - 1][key]) / np.log(
                    records[i]["n_dofs"] / records[i - 1]["n_dofs"])
        ds[key.replace("error", "order")] = (run, order, {"long_name": f"observed order of {key} per DOF^(-1/2)"})
    ds.attrs.update({
        "title": "vemkit: k = 1 against k = 2 virtual elements on the paper's scene (Section 4 study)",
        "error_measure": "relative errors of Pi_k u_h against Pi_2 u_ref (k = 2 reference on fine squares), broken "
                         "over the reference cells (vemkit.vem.norms_k2.projection_error_k2); error_contact_l2: "
                         "||u_h - u_ref||_L2(Gamma_C) / ||u_ref||; error_paper: SPEC 5 against the k = 1 2^-8 "
                         "reference (k = 1 only); share_*: part of the squared H1-seminorm error within "
                         f"{settings['region_radius']} of a corner or of the contact-zone boundary",
        "contact_zone_boundary": str(boundary), "settings": str(settings), "git_commit": git_commit(),
        "package_versions": str(package_versions())})
    return ds


def markdown(ds, boundary):
    import numpy as np

    lines = ["# k = 1 against k = 2 on the paper's scene (Section 4 study)", "",
             f"Errors relative to a k = 2 reference on fine squares; contact-zone boundary of the reference at "
             f"{boundary}. Orders per DOF: p = -2 dlog e / dlog N.", "",
             "| case | n | DOFs | " + " | ".join(f"{LABELS[k]} | order" for k in ERRORS)
             + " | share near corners x=0 | share near contact-zone boundary |",
             "|---|---|---|" + "---|---|" * len(ERRORS) + "---|---|"]
    for i in range(ds.sizes["run"]):
        row = ds.isel(run=i)
        cells = [f"{float(row[k]):.3e} | {float(row[k.replace('error', 'order')]):.2f}" for k in ERRORS]
        left = float(row["share_corner_xmin_ymin"] + row["share_corner_xmin_ymax"])
        lines.append(f"| {str(row['case'].values)} | {int(row['n'])} | {int(row['n_dofs'])} | " + " | ".join(cells)
                     + f" | {left:.2f} | {float(row['share_contact_zone_boundary']):.3f} |")
    lines += ["", "Finest-interval orders:", ""]
    for case in dict.fromkeys(ds["case"].values.tolist()):
        last = ds.where(ds["case"] == case, drop=True).isel(run=-1)
        lines.append(f"- {case}: " + ", ".join(f"{LABELS[k]} {float(last[k.replace('error', 'order')]):.2f}"
                                               for k in ERRORS if np.isfinite(float(last[k.replace('error', 'order')]))))
    lines += ["", "At equal DOFs: the error of the uniform case, log-log interpolated at the DOFs of the other case's "
              "finest level, against that case's error (same order k):", ""]
    lines += equal_dof_comparison(ds)
    return "\n".join(lines).replace("nan", "-") + "\n"


def equal_dof_comparison(ds, uniform="square", keys=("error_h1", "error_l2", "error_contact_l2")):
    """Lines comparing each non-uniform case with the uniform case of the same order at its finest DOFs."""
    import numpy as np

    lines = []
    cases = list(dict.fromkeys(ds["case"].values.tolist()))
    for case in cases:
        part = ds.where(ds["case"] == case, drop=True)
        order, family = int(part["order"].values[0]), str(part["family"].values[0])
        base = [c for c in cases if c.startswith(uniform) and int(ds.where(ds["case"] == c, drop=True)["order"].values[0]) == order]
        if family == uniform or not base:
            continue
        ref = ds.where(ds["case"] == base[0], drop=True)
        dofs = float(part["n_dofs"].values[-1])
        ratios = []
        for key in keys:
            interpolated = np.exp(np.interp(np.log(dofs), np.log(ref["n_dofs"].values.astype(float)),
                                            np.log(ref[key].values)))
            ratios.append(f"{LABELS[key]} {float(part[key].values[-1]):.3e} against {interpolated:.3e} "
                          f"(x{interpolated / float(part[key].values[-1]):.2f})")
        lines.append(f"- {case} at {int(dofs)} DOFs vs {base[0]}: " + "; ".join(ratios))
    return lines


with logged(smk):
    import json

    from vemkit.studies.sweeps import write_dataset

    records, boundary = [], None
    for path in smk.input:
        with open(path, encoding="utf-8") as stream:
            data = json.load(stream)
        records += data["records"]
        boundary = data["contact_zone_boundary"]
    ds = dataset(records, smk.params.settings, boundary)
    write_dataset(ds, smk.output.nc)
    text = markdown(ds, boundary)
    with open(smk.output.md, "w", encoding="utf-8") as stream:
        stream.write(text)
    print(text)
