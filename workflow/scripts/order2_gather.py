"""Rules order2_gather and order2_manufactured_gather: every run of the Section 4 study in one netCDF
file, the observed orders and the Markdown table (one section per study: the paper's scene, or each
manufactured contact solution).

Orders are per degree of freedom, p = -2 dlog(error) / dlog(DOFs) between consecutive levels of a
case: on uniform meshes (DOFs ~ h^-2) it is the order in h; on meshes refined at Gamma_C it says what
the refinement buys per DOF. k = 2 counts every degree of freedom of the space (vertex values, edge
and cell means; the cell means are condensed out of the solve: n_unknowns).
"""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
LABELS = {
    "error_h1": "H1",
    "error_h1_semi": "H1 semi",
    "error_l2": "L2",
    "error_contact_l2": "L2(Gamma_C)",
    "error_interpolation_contact_l2": "u - I_h u on Gamma_C",
    "error_paper": "paper's measure",
}
LABELS_ONLY = ("study", "case", "n", "family", "contact_zone_boundary")


def error_keys(records):
    return [k for k in LABELS if k in records[0]]


def dataset(records, settings, title, measure):
    import numpy as np
    import xarray as xr

    from vemkit.io.provenance import git_commit, package_versions

    run = "run"
    ds = xr.Dataset(
        coords={
            "study": (run, [r["study"] for r in records]),
            "case": (run, [r["case"] for r in records]),
            "n": (run, [r["n"] for r in records]),
        }
    )
    for key in [k for k in records[0] if k not in LABELS_ONLY]:
        ds[key] = (
            run,
            np.array(
                [r.get(key, np.nan) for r in records],
                dtype=float if "error" in key or "share" in key or key == "wall_time" else np.int64,
            ),
        )
    ds["family"] = (run, [r["family"] for r in records])
    if "contact_zone_boundary" in records[0]:  # the discrete solution's first change of contact state
        ds["contact_zone_boundary_x"] = (
            run,
            [(r["contact_zone_boundary"] or [np.nan])[0] for r in records],
            {"long_name": "x where the discrete solution's contact state changes"},
        )
    for key in error_keys(records):
        order = np.full(len(records), np.nan)
        for i in range(1, len(records)):
            if (records[i]["study"], records[i]["case"]) == (records[i - 1]["study"], records[i - 1]["case"]):
                order[i] = (
                    -2
                    * np.log(records[i][key] / records[i - 1][key])
                    / np.log(records[i]["n_dofs"] / records[i - 1]["n_dofs"])
                )
        ds[key.replace("error", "order")] = (run, order, {"long_name": f"observed order of {key} per DOF^(-1/2)"})
    ds.attrs.update(
        {
            "title": f"vemkit: {title}",
            "error_measure": f"{measure}; {MEASURES}",
            "settings": str(settings),
            "git_commit": git_commit(),
            "package_versions": str(package_versions()),
        }
    )
    return ds


MEASURES = (
    "relative errors of Pi_k u_h; error_contact_l2: ||u - u_h||_L2(Gamma_C) / ||u||; "
    "error_interpolation_contact_l2: ||u - I_h u||_L2(Gamma_C) / ||u||, I_h the interpolant of order k; "
    "error_paper: the paper's measure (docs/reference/mathematics.md) against the k = 1 2^-8 reference (k = 1, paper scene only); share_*: part of the "
    "squared H1-seminorm error within region_radius of a corner or of the contact-zone boundary"
)


def study_table(part, keys):
    """The Markdown rows of one study."""
    shares = "share_corner_xmin_ymin" in part
    zone = "contact_zone_boundary_x" in part
    lines = [
        "| case | n | DOFs | "
        + " | ".join(f"{LABELS[k]} | order" for k in keys)
        + (" | share near corners x=0 | share near contact-zone boundary" if shares else "")
        + (" | contact-zone boundary x" if zone else "")
        + " |",
        "|---|---|---|" + "---|---|" * len(keys) + ("---|---|" if shares else "") + ("---|" if zone else ""),
    ]
    for i in range(part.sizes["run"]):
        row = part.isel(run=i)
        cells = [f"{float(row[k]):.3e} | {float(row[k.replace('error', 'order')]):.2f}" for k in keys]
        extra = ""
        if shares:
            left = float(row["share_corner_xmin_ymin"] + row["share_corner_xmin_ymax"])
            extra += f" | {left:.2f} | {float(row['share_contact_zone_boundary']):.3f}"
        if zone:
            extra += f" | {float(row['contact_zone_boundary_x']):.4f}"
        lines.append(
            f"| {str(row['case'].values)} | {int(row['n'])} | {int(row['n_dofs'])} | "
            + " | ".join(cells)
            + extra
            + " |"
        )
    return lines


def markdown(ds, keys, title, measure, boundary):
    import numpy as np

    lines = [
        f"# {title}",
        "",
        f"{measure}. Orders per DOF: p = -2 dlog e / dlog N; 'u - I_h u on Gamma_C': "
        "the interpolant of order k of the exact (or reference) solution, the term of the paper's estimate.",
    ]
    if boundary is not None:
        lines[-1] += f" Contact-zone boundary of the reference at {boundary}."
    for study in dict.fromkeys(ds["study"].values.tolist()):
        part = ds.where(ds["study"] == study, drop=True)
        lines += ["", f"## {study}", ""] + study_table(part, keys) + ["", "Finest-interval orders:", ""]
        for case in dict.fromkeys(part["case"].values.tolist()):
            last = part.where(part["case"] == case, drop=True).isel(run=-1)
            lines.append(
                f"- {case}: "
                + ", ".join(
                    f"{LABELS[k]} {float(last[k.replace('error', 'order')]):.2f}"
                    for k in keys
                    if np.isfinite(float(last[k.replace("error", "order")]))
                )
            )
        lines += [
            "",
            "At equal DOFs: the error of the uniform case, log-log interpolated at the DOFs of the other "
            "case's finest level, against that case's error (same order k):",
            "",
        ]
        lines += equal_dof_comparison(part)
    return "\n".join(lines).replace("nan", "-") + "\n"


def equal_dof_comparison(ds, uniform="square", keys=("error_h1", "error_l2", "error_contact_l2")):
    """Lines comparing each non-uniform case with the uniform case of the same order at its finest DOFs."""
    import numpy as np

    lines = []
    cases = list(dict.fromkeys(ds["case"].values.tolist()))
    for case in cases:
        part = ds.where(ds["case"] == case, drop=True)
        order, family = int(part["order"].values[0]), str(part["family"].values[0])
        base = [
            c
            for c in cases
            if c.startswith(uniform) and int(ds.where(ds["case"] == c, drop=True)["order"].values[0]) == order
        ]
        if family == uniform or not base:
            continue
        ref = ds.where(ds["case"] == base[0], drop=True)
        dofs = float(part["n_dofs"].values[-1])
        ratios = []
        for key in keys:
            interpolated = np.exp(
                np.interp(np.log(dofs), np.log(ref["n_dofs"].values.astype(float)), np.log(ref[key].values))
            )
            ratios.append(
                f"{LABELS[key]} {float(part[key].values[-1]):.3e} against {interpolated:.3e} "
                f"(x{interpolated / float(part[key].values[-1]):.2f})"
            )
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
        boundary = data.get("contact_zone_boundary", boundary)
    title, measure = smk.params.title, smk.params.measure
    ds = dataset(records, smk.params.settings, title, measure)
    if boundary is not None:
        ds.attrs["contact_zone_boundary"] = str(boundary)
    write_dataset(ds, smk.output.nc)
    text = markdown(ds, error_keys(records), title, measure, boundary)
    with open(smk.output.md, "w", encoding="utf-8") as stream:
        stream.write(text)
    print(text)
