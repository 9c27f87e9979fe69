"""The Snakemake workflow (dry runs only: nothing is solved) and the modules behind its tables.

- the default target plans every rule of the study, and nothing else;
- ``results/table1.nc`` plans only meshes, solves and errors of the square family (no figure);
- ``batch_levels: false`` gives one job per mesh and per solve;
- a bad configuration is rejected with one line naming the key;
- ``vemkit.studies.convergence``: orders, the Dataset, no NaN in the file; ``vemkit.report.tables``: ratios.
"""

from __future__ import annotations

import csv
import io
import math
import re
import shutil
import subprocess
import sys
from pathlib import Path

import netCDF4
import numpy as np
import pytest
import xarray as xr
import yaml

from vemkit.io.fill_values import FLOAT_FILL, INT_FILL
from vemkit.report import tables
from vemkit.studies.convergence import (
    convergence_dataset,
    convergence_orders,
    read_convergence,
    with_paper_variant,
    write_convergence,
)
from vemkit.studies.paper import PAPER_TABLE1

ROOT = Path(__file__).resolve().parents[2]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
FIGURE_RULES = {"figure_fields", "figure_deformed", "figure_contact", "figure_convergence"}


def _snakemake():
    exe = Path(sys.executable).with_name("snakemake")
    return str(exe) if exe.exists() else shutil.which("snakemake")


def dry_run(*args) -> subprocess.CompletedProcess:
    exe = _snakemake()
    if exe is None:
        pytest.skip("snakemake is not installed")
    return subprocess.run(
        [exe, "--dry-run", "--forceall", "--nolock", "--cores", "2", *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )


def planned_jobs(*args) -> dict:
    """{rule: count} from the job stats of a dry run."""
    run = dry_run(*args)
    assert run.returncode == 0, run.stdout + run.stderr
    text = run.stdout + run.stderr
    stats = text[text.index("Job stats:") :]
    stats = stats[: stats.index("total")]
    return {m.group(1): int(m.group(2)) for m in re.finditer(r"^(\w+)\s+(\d+)\s*$", stats, re.M)}


def _families():
    meshes = CONFIG["meshes"]
    triangles = [f for f in CONFIG["convergence"] if meshes[f]["family"] == "triangle"]
    return triangles, [f for f in CONFIG["convergence"] if f not in triangles]


# -- the DAG ----------------------------------------------------------------------------------
def test_default_target_plans_the_whole_study():
    jobs = planned_jobs()
    assert set(jobs) == {
        "all",
        "mesh",
        "mesh_levels",
        "solve",
        "solve_levels",
        "errors",
        "errors_gauss",
        "table1_dataset",
        "convergence_dataset",
        "table",
        *FIGURE_RULES,
    }
    triangles, others = _families()
    stabs = len(CONFIG["stabilizations"])
    assert jobs["mesh_levels"] == len(set(CONFIG["convergence"]) | {CONFIG["table1"]["mesh"]})
    # one solve per (family, stabilization) of the levels; triangles once (no stabilization)
    assert jobs["solve_levels"] == stabs * len(others) + len(triangles)
    assert jobs["errors"] == len(CONFIG["convergence"])
    assert jobs["figure_fields"] == len(CONFIG["figures"]["fields"])
    assert jobs["table"] == 2
    assert "archive" not in jobs  # the archive is refreshed on purpose only


def test_table1_target_builds_only_its_inputs():
    jobs = planned_jobs("results/table1.nc")
    assert not FIGURE_RULES & set(jobs)
    assert not {"table", "convergence_dataset", "all"} & set(jobs)
    stabs = len(CONFIG["stabilizations"])
    assert jobs["errors"] == 1  # the square family only
    assert jobs["errors_gauss"] == 1  # table1.gauss: its own solves, on the same mesh files
    assert jobs["solve_levels"] == stabs
    assert jobs["solve"] == stabs  # the 2^-8 references
    assert jobs["mesh_levels"] == 1 and jobs["mesh"] == 1


def test_one_job_per_solve_without_batching():
    jobs = planned_jobs("--config", "batch_levels=False")
    assert "solve_levels" not in jobs and "mesh_levels" not in jobs
    triangles, others = _families()
    stabs, levels = len(CONFIG["stabilizations"]), len(CONFIG["levels"])
    extra = {(f["mesh"], f["n"]) for f in CONFIG["figures"]["fields"].values()} - {
        (f, n) for f in CONFIG["convergence"] for n in CONFIG["levels"]
    }
    assert jobs["solve"] == levels * (stabs * len(others) + len(triangles)) + stabs + len(extra)


def test_figure_target_does_not_solve_the_reference():
    jobs = planned_jobs("results/figures/fig6.png")
    assert set(jobs) == {"mesh_levels", "solve_levels", "figure_deformed"}


@pytest.mark.parametrize(
    "bad, key",
    [
        ({"bogus_key": 1}, "bogus_key"),
        ({"levels": [4, "eight"]}, "levels[1]"),
        ({"stabilizations": ["dofi", "dofi-3mu"]}, "stabilizations[1]"),
        ({"meshes": {"square": {"family": "square", "colour": "red"}}}, "colour"),
        ({"convergence": ["square", "no-such-family"]}, "no-such-family"),
        ({"levels": [4, 512]}, "512"),
    ],
)
def test_bad_config_is_rejected_with_the_key(tmp_path, bad, key):
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(bad))
    run = dry_run("--configfile", str(path))
    assert run.returncode != 0
    message = run.stdout + run.stderr
    assert key in message
    assert "config" in message


# -- the studies' configuration: Snakemake's config, merged with --configfile -----------------------
def _sweep_config(tmp_path, figure_x):
    spec = {
        "sweeps": {
            "mine": {
                "overrides": ["discretization.mesh.n=8"],
                "parts": 2,
                "grid": {"contact.normal.k": [1.0, 10.0], "contact.friction.k": [0.0, 450.0]},
                "figures": {"map": {"x": figure_x, "y": "k_tau", "quantities": ["normal_force"]}},
            }
        }
    }
    path = tmp_path / "my-sweeps.yaml"
    path.write_text(yaml.safe_dump(spec))
    return str(path)


def test_a_configfile_adds_a_sweep_named_by_the_package_dimensions(tmp_path):
    jobs = planned_jobs("results/sweeps/mine/map.png", "--configfile", _sweep_config(tmp_path, "k_nu"))
    assert jobs.get("sweep_part") == 2 and jobs.get("sweep") == 1 and jobs.get("sweep_figure") == 1


def test_a_sweep_figure_on_an_unknown_dimension_is_rejected(tmp_path):
    run = dry_run("results/sweeps/mine/map.png", "--configfile", _sweep_config(tmp_path, "contact_normal_k"))
    message = run.stdout + run.stderr
    assert run.returncode != 0
    assert "sweeps.mine.figures.map" in message and "k_nu" in message and "Traceback" not in message


@pytest.mark.parametrize(
    "bad, key",
    [
        ({"sweep_defaults": {"parts": 0}}, "sweep_defaults.parts"),
        ({"stability": {"n": "sixteen"}}, "stability.n"),
        ({"studies_bogus": 1}, "studies_bogus"),
    ],
)
def test_bad_studies_config_is_rejected_with_the_key(tmp_path, bad, key):
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(bad))
    run = dry_run("extras", "--configfile", str(path))
    assert run.returncode != 0
    assert key in run.stdout + run.stderr


# -- vemkit.studies.convergence -----------------------------------------------------------------------
def test_orders_of_a_power_law():
    h = 2.0 ** -np.arange(2, 7)
    orders = convergence_orders(h, 3.0 * h**1.5)
    assert np.isnan(orders[0])
    assert np.allclose(orders[1:], 1.5)
    # any input order; a missing level is skipped (order against the next coarser level)
    shuffled = np.array([3, 0, 4, 1, 2])
    assert np.allclose(convergence_orders(h[shuffled], 3.0 * h[shuffled] ** 1.5)[shuffled != 0], 1.5)
    e = 3.0 * h**1.5
    e[2] = np.nan
    o = convergence_orders(h, e)
    assert np.isnan(o[2]) and np.isclose(o[3], 1.5)


def _records(families=("square", "voronoi"), stabs=("dofi", "trace"), levels=(4, 8, 16, 32, 64), p=1.0):
    out = []
    for i, f in enumerate(families):
        for j, s in enumerate(stabs):
            for n in levels:
                e = (0.7 + 0.1 * i + 0.05 * j) * (4.0 / n) ** p
                out.append(
                    {
                        "family": f,
                        "stabilization": s,
                        "n": n,
                        "h": 1 / n,
                        "error_h1": e,
                        "error_h1_semi": 1.1 * e,
                        "error_l2": 0.1 * e,
                        "error_paper": 1.2 * e,
                        "n_dofs": 2 * (n + 1) ** 2,
                        "n_cells": n * n,
                        "iterations": 3,
                        "wall_time": 0.01 * n,
                        "assembly_time": 0.001,
                        "h_max": math.sqrt(2) / n,
                    }
                )
    return out


def test_convergence_dataset_layout_and_attributes():
    ds = convergence_dataset(
        _records(p=1.0), scene_yaml="name: paper\n", parameters={"levels": [4, 8]}, commit="abc123"
    )
    assert ds["error_h1"].dims == ("family", "stabilization", "h")
    assert list(ds["h"].values) == [0.25, 0.125, 0.0625, 0.03125, 0.015625]  # coarse to fine
    assert list(ds["n"].values) == [4, 8, 16, 32, 64]
    for name in (
        "error_h1",
        "error_h1_semi",
        "order",
        "error_paper",
        "order_paper",
        "n_dofs",
        "iterations",
        "wall_time",
    ):
        assert name in ds
    assert np.isnan(ds["order"].isel(h=0)).all()
    assert np.allclose(ds["order"].isel(h=slice(1, None)), 1.0)
    assert np.allclose(ds["order_paper"].isel(h=slice(1, None)), 1.0)
    assert (ds["order_defined"].isel(h=0) == 0).all() and (ds["order_defined"].isel(h=slice(1, None)) == 1).all()
    assert ds.attrs["scene"] == "name: paper\n"
    assert ds.attrs["git_commit"] == "abc123"
    assert {"numpy", "scipy", "numba", "pyamg", "xarray", "vemkit"} <= set(eval_json(ds.attrs["package_versions"]))
    assert eval_json(ds.attrs["parameters"]) == {"levels": [4, 8]}


def eval_json(text):
    import json

    return json.loads(text)


def test_no_nan_is_stored(tmp_path):
    records = [r for r in _records() if not (r["family"] == "voronoi" and r["n"] == 64)]
    ds = convergence_dataset(records, scene_yaml="x", commit="c")
    path = write_convergence(ds, tmp_path / "c.nc")
    with netCDF4.Dataset(path) as nc:
        nc.set_auto_mask(False)
        for name, var in nc.variables.items():
            values = var[:]
            if np.issubdtype(values.dtype, np.floating):
                assert np.isfinite(values).all(), f"{name} holds NaN/inf in the file"
        assert nc["order"].getncattr("_FillValue") == FLOAT_FILL
        assert (nc["order"][:, :, 0] == FLOAT_FILL).all()
        assert (nc["error_h1"][1, :, -1] == FLOAT_FILL).all()  # voronoi has no n = 64
        assert nc["n_dofs"].getncattr("_FillValue") == INT_FILL
        assert (nc["n_dofs"][1, :, -1] == INT_FILL).all()
        assert "_FillValue" not in nc["h"].ncattrs()
        assert (nc["defined"][1, :, -1] == 0).all()
    # read back: undefined entries masked, the rest exact
    back = read_convergence(path)
    assert np.isnan(back["order"].isel(h=0)).all()
    assert np.isnan(back["error_h1"].sel(family="voronoi", h=1 / 64)).all()
    xr.testing.assert_allclose(back["error_h1"].sel(family="square"), ds["error_h1"].sel(family="square"))
    assert back["n_dofs"].dtype == np.int64


def test_a_complete_study_has_no_fill_value_but_order(tmp_path):
    path = write_convergence(convergence_dataset(_records(), scene_yaml="x", commit="c"), tmp_path / "c.nc")
    with netCDF4.Dataset(path) as nc:
        filled = {name for name, var in nc.variables.items() if "_FillValue" in var.ncattrs()}
    assert filled == {"order", "order_h1_semi", "order_paper"}
    assert xr.open_dataset(path)["n_dofs"].dtype == np.int64


def test_bad_records_are_rejected():
    records = _records()
    with pytest.raises(ValueError, match="two error records"):
        convergence_dataset(records + records[:1], commit="c")
    broken = [dict(records[0], error_h1=float("nan"))] + records[1:]
    with pytest.raises(ValueError, match="error_h1"):
        convergence_dataset(broken, commit="c")
    with pytest.raises(ValueError, match="no error records"):
        convergence_dataset([], commit="c")


# -- vemkit.report.tables ------------------------------------------------------------------------------
def test_paper_constants_are_consistent():
    h, e, o = (np.array(PAPER_TABLE1[k], dtype=float) for k in ("h", "error", "order"))
    assert np.allclose(h, 1.0 / np.array(PAPER_TABLE1["n"]))
    computed = np.log2(e[:-1] / e[1:])
    assert np.allclose(computed, o[1:], atol=2e-4)  # the paper's orders are log2 of its error ratios


def _paper_like(scale):
    records = []
    for s, factor in scale.items():
        for n, e in zip(PAPER_TABLE1["n"], PAPER_TABLE1["error"]):
            records.append(
                {
                    "family": "square",
                    "stabilization": s,
                    "n": n,
                    "error_h1": factor * e,
                    "error_h1_semi": 2.0 * factor * e,
                    "error_paper": (1 + (factor - 1) / 100) * e,
                    "n_dofs": 10,
                    "iterations": 1,
                    "wall_time": 0.1,
                }
            )
    return convergence_dataset(records, scene_yaml="x", commit="c")


def test_table1_ratios_and_orders():
    ds = _paper_like({"dofi": 1.05, "trace": 0.8})
    rows = tables.table1_rows(ds)
    h1 = [r for r in rows if r["norm"] == "h1"]
    assert len(h1) == 10
    for r in h1:
        assert math.isclose(r["ratio"], 1.05 if r["stabilization"] == "dofi" else 0.8)
        if r["n"] == 4:
            assert r["order"] is None and r["order_difference"] is None
        else:
            assert abs(r["order_difference"]) < 2e-4  # a constant factor keeps the (rounded) orders
    summary = tables.table1_summary(ds)
    assert summary[0]["stabilization"] == "dofi" and summary[0]["norm"] == "paper"
    assert summary[0]["meets_target"]  # 0.05 % <= 0.1 %
    assert next(s for s in summary if s["stabilization"] == "dofi" and s["norm"] == "h1")["meets_target"]
    trace = next(s for s in summary if s["stabilization"] == "trace" and s["norm"] == "h1")
    assert not trace["meets_target"] and math.isclose(trace["max_error_deviation"], 0.2)
    trace_paper = next(s for s in summary if s["stabilization"] == "trace" and s["norm"] == "paper")
    assert not trace_paper["meets_target"] and math.isclose(trace_paper["max_error_deviation"], 0.002)


def test_table1_shows_the_papers_measure_first_with_five_digits():
    ds = _paper_like({"dofi": 1.05, "dofi-2mu": 1.00002})
    ds.attrs["scene"] = "name: paper\ndiscretization: {stabilization: dofi-2mu}\n"
    lines = [line for line in tables.table1_markdown(ds).splitlines() if line.startswith("| ")]
    assert lines[1].startswith("| paper | Table 1 | error | 1.9114e-01 |")
    # the scene's stabilization first, the paper's measure first, ratios at 5 significant digits
    assert lines[3] == (
        "| dofi-2mu | paper's measure | error | 1.9114e-01 | 1.0309e-01 | 5.4352e-02 | 2.8007e-02 | 1.3828e-02 |"
    )
    assert lines[4].startswith("| dofi-2mu | paper's measure | ratio to paper | 1.0000 | 1.0000 |")
    assert re.fullmatch(r"\| dofi-2mu \| paper's measure \| order − paper \| – (\| [+-]0\.000\d\d ){4}\|", lines[6])
    assert "| dofi | paper's measure | ratio to paper | 1.0005 |" in "\n".join(lines)


def test_the_gauss_variant_sits_beside_the_papers_measure(tmp_path):
    ds = _paper_like({"dofi-2mu": 1.002, "trace": 0.9})
    gauss = [
        {"family": "square", "stabilization": "dofi-2mu", "n": n, "error_paper": e * 1.00001}
        for n, e in zip(PAPER_TABLE1["n"], PAPER_TABLE1["error"])
    ]
    ds = with_paper_variant(ds, gauss, "gauss", "3 Gauss points")
    back = read_convergence(write_convergence(ds, tmp_path / "t.nc"))
    assert np.isnan(back["error_paper_gauss"].sel(stabilization="trace")).all()
    assert np.allclose(
        back["order_paper_gauss"].sel(stabilization="dofi-2mu").isel(h=slice(1, None)),
        back["order_paper"].sel(stabilization="dofi-2mu").isel(h=slice(1, None)),
    )
    measures = [
        line.split(" | ")[:2]
        for line in tables.table1_markdown(back).splitlines()
        if line.startswith("| ") and "| error |" in line
    ]
    assert measures[:4] == [
        ["| paper", "Table 1"],
        ["| dofi-2mu", "paper's measure"],
        ["| dofi-2mu", "paper's measure, Gauss on Γ_C"],
        ["| trace", "paper's measure"],
    ]
    summary = {(s["stabilization"], s["norm"]): s for s in tables.table1_summary(back)}
    assert summary[("dofi-2mu", "paper_gauss")]["meets_target"] and ("trace", "paper_gauss") not in summary


def test_records_without_the_papers_measure_keep_the_old_layout():
    records = [{k: v for k, v in r.items() if k != "error_paper"} for r in _records()]
    ds = convergence_dataset(records, scene_yaml="x", commit="c")
    assert "error_paper" not in ds and "order_paper" not in ds
    assert {r["norm"] for r in tables.table1_rows(ds)} == {"h1", "h1_semi"}
    assert "| paper |" not in tables.convergence_markdown(ds).replace("| paper | Table 1", "")


def test_table1_formats():
    ds = _paper_like({"dofi": 1.05, "trace": 0.8})
    md = tables.table1_markdown(ds)
    assert "| dofi | H1 | ratio to paper | 1.0500 | 1.0500 |" in md
    assert "h = 2^-2" in md and "closest to the paper: dofi" in md
    rows = list(csv.DictReader(io.StringIO(tables.table1_csv(ds))))
    assert len(rows) == 30 and {r["norm"] for r in rows} == {"paper", "h1", "h1_semi"}
    assert rows[0]["norm"] == "paper" and math.isclose(float(rows[1]["ratio"]), 1.0005)
    assert math.isclose(float(next(r for r in rows if r["norm"] == "h1" and r["n"] == "8")["ratio"]), 1.05)
    assert rows[0]["order"] == ""  # undefined at the coarsest h: empty, not NaN
    tex = tables.table1_latex(ds)
    assert tex.count(r"\begin{tabular}") == 1 and r"$h = 2^{-6}$" in tex and "nan" not in tex.lower()
    conv = tables.convergence_markdown(ds)
    assert "| square | dofi | paper |" in conv and "| square | dofi | H1 |" in conv and "nan" not in conv.lower()
    assert len(list(csv.DictReader(io.StringIO(tables.convergence_csv(ds))))) == 10


# -- vemkit.report.figures (smoke) -------------------------------------------------------------------------
def test_plots_draw(tmp_path):
    from vemkit.mesh.families import build_mesh
    from vemkit.report import figures as plots

    ds = _paper_like({"dofi": 1.05, "trace": 0.8})
    out = plots.save(plots.convergence_figure(ds), tmp_path / "c.png", tmp_path / "c.pdf")
    assert all(p.stat().st_size > 1000 for p in out)
    paper_fig = plots.convergence_figure(ds, norm="paper")
    assert "paper, Table 1" in [t.get_text() for t in paper_fig.axes[0].get_legend().get_texts()]
    from vemkit.exceptions import ResultError

    with pytest.raises(ResultError, match="error_paper"):
        plots.convergence_figure(ds.drop_vars(["error_paper", "order_paper"]), norm="paper")
    mesh = build_mesh("voronoi", 4, seed=1)
    x, y = mesh.vertices.T
    fig = plots.displacement_figure(mesh, x * y, x - y, title="smoke")
    assert plots.save(fig, tmp_path / "f.png")[0].stat().st_size > 1000
    assert plots.auto_magnification(np.array([0.3])) == 0.5


def test_a_3d_studies_scene_plans_its_sweep_and_stability_matrix():
    """config/sweeps3d.yaml: the sweeps and the stability matrix on the sheared box (model: 3d)."""
    jobs = planned_jobs(
        "results/sweeps/box3d.nc",
        "results/sweeps/box3d/profiles.png",
        "results/stability/stability.md",
        "--configfile",
        "config/sweeps3d.yaml",
    )
    assert jobs.get("sweep_part") == 1 and jobs.get("sweep_figure") == 1 and jobs.get("stability_part") == 1, jobs
