"""Rule three_d_figure: the deformed boundary of a 3D solution coloured by von Mises (matplotlib 3D,
a Poly3DCollection of the boundary faces)."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    from vemkit.io.solution_file import read_solution
    from vemkit.studies.three_d import boundary_polygons

    mesh, ds = read_solution(smk.input[0])
    u = np.stack([ds[c].values for c in ("u1", "u2", "u3")], axis=1)
    size = float(np.ptp(mesh.vertices, axis=0).max())
    scale = smk.params.magnification * 0.1 * size / max(float(np.abs(u).max()), 1e-300)  # largest: 10 % x magnification
    polygons, cells = boundary_polygons(mesh, u, scale)
    vm = ds["von_mises"].values[cells]
    norm = matplotlib.colors.Normalize(vmin=float(vm.min()), vmax=float(vm.max()))
    fig = plt.figure(figsize=(6.4, 5.2))
    ax = fig.add_subplot(projection="3d")
    ax.add_collection3d(
        Poly3DCollection(polygons, facecolors=plt.cm.viridis(norm(vm)), edgecolors="k", linewidths=0.15)
    )
    points = np.concatenate(polygons)
    lo, hi = points.min(axis=0), points.max(axis=0)
    ax.set_xlim(lo[0], hi[0]), ax.set_ylim(lo[1], hi[1]), ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(np.maximum(hi - lo, 0.05 * size))
    ax.set_xlabel("x"), ax.set_ylabel("y"), ax.set_zlabel("z")
    ax.locator_params(axis="z", nbins=3)
    ax.view_init(elev=25, azim=-55)
    fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap="viridis"), ax=ax, shrink=0.7, label="von Mises stress")
    import yaml

    family = (
        (yaml.safe_load(ds.attrs.get("scene", "")) or {}).get("discretization", {}).get("mesh", {}).get("family", "")
    )
    ax.set_title(f"{smk.wildcards.case}: {mesh.n_cells} cells ({family}), displacement x {scale:.3g}", fontsize=9)
    fig.savefig(smk.output[0], dpi=150, bbox_inches="tight")
    print(f"{smk.output[0]}: {len(polygons)} boundary faces, von Mises {vm.min():.3g} ... {vm.max():.3g}")
