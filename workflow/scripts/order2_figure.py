"""Rule order2_figure: errors against DOFs, log-log, k = 1 and k = 2, uniform and refined at Gamma_C."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
PANELS = (("error_h1", "H1 (full norm)"), ("error_l2", "L2"), ("error_contact_l2", "L2 on Gamma_C"))
SLOPES = ((1.0, ":"), (1.5, "--"), (2.0, "-."))  # orders in h: e ~ N^(-p/2)

with logged(smk):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from vemkit.studies.sweeps import read_dataset

    ds = read_dataset(smk.input[0])
    fig, axes = plt.subplots(1, len(PANELS), figsize=(5 * len(PANELS), 4.2), constrained_layout=True)
    for ax, (key, title) in zip(axes, PANELS, strict=True):
        for case in dict.fromkeys(ds["case"].values.tolist()):
            part = ds.where(ds["case"] == case, drop=True)
            order = int(part["order"].values[0])
            ax.loglog(part["n_dofs"], part[key], marker="o" if order == 2 else "s",
                      linestyle="-" if "refined" not in case else "--", label=case)
        dofs = np.array([float(ds["n_dofs"].min()), float(ds["n_dofs"].max())])
        top = float(ds[key].max())
        for p, style in SLOPES:
            ax.loglog(dofs, top * (dofs / dofs[0]) ** (-p / 2), color="grey", linestyle=style, linewidth=0.8,
                      label=f"h^{p:g}")
        ax.set_xlabel("degrees of freedom")
        ax.set_ylabel("relative error")
        ax.set_title(title)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle("Paper scene: k = 1 vs k = 2 against a k = 2 reference")
    fig.savefig(smk.output[0], dpi=150)
