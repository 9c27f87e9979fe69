"""Rule order2_figure: errors against DOFs, log-log, k = 1 and k = 2, uniform and refined at Gamma_C;
one row per study (the paper's scene, or each manufactured contact solution). The Gamma_C panel also
draws ||u - I_h u|| (thin, dotted), the interpolation term of the paper's estimate."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
PANELS = (("error_h1", "H1 (full norm)"), ("error_l2", "L2"), ("error_contact_l2", "L2 on Gamma_C"))
SLOPES = ((1.0, ":"), (1.5, "--"), (2.0, "-."), (3.0, (0, (1, 4))))  # orders in h: e ~ N^(-p/2)


def draw(ax, ds, key, title):
    import numpy as np

    for number, case in enumerate(dict.fromkeys(ds["case"].values.tolist())):
        part = ds.where(ds["case"] == case, drop=True)
        order = int(part["order"].values[0])
        (line,) = ax.loglog(
            part["n_dofs"],
            part[key],
            marker="o" if order == 2 else "s",
            linestyle="-" if "refined" not in case else "--",
            label=case,
            color=f"C{number}",
        )
        if key == "error_contact_l2" and "error_interpolation_contact_l2" in part:
            ax.loglog(
                part["n_dofs"],
                part["error_interpolation_contact_l2"],
                linestyle=":",
                linewidth=0.9,
                color=line.get_color(),
                label=f"{case}: u - I_h u",
            )
    dofs = np.array([float(ds["n_dofs"].min()), float(ds["n_dofs"].max())])
    top = float(ds[key].max())
    for p, style in SLOPES:
        ax.loglog(
            dofs, top * (dofs / dofs[0]) ** (-p / 2), color="grey", linestyle=style, linewidth=0.8, label=f"h^{p:g}"
        )
    ax.set_xlabel("degrees of freedom")
    ax.set_ylabel("relative error")
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)


with logged(smk):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from vemkit.studies.sweeps import read_dataset

    ds = read_dataset(smk.input[0])
    studies = list(dict.fromkeys(ds["study"].values.tolist())) if "study" in ds else ["paper"]
    fig, axes = plt.subplots(
        len(studies), len(PANELS), figsize=(5 * len(PANELS), 4.2 * len(studies)), constrained_layout=True, squeeze=False
    )
    for row, study in zip(axes, studies, strict=True):
        part = ds.where(ds["study"] == study, drop=True) if "study" in ds else ds
        for ax, (key, title) in zip(row, PANELS, strict=True):
            draw(ax, part, key, f"{study}: {title}")
    axes[0, 0].legend(fontsize=7)
    axes[0, -1].legend(fontsize=6)
    fig.suptitle(str(ds.attrs.get("title", "Section 4 study")).removeprefix("vemkit: "))
    fig.savefig(smk.output[0], dpi=130)
