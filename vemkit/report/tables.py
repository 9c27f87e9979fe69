"""Table 1 of the paper next to ours (Markdown, CSV, LaTeX), and the convergence tables.

``PAPER_TABLE1`` holds the paper's numbers (docs/reference/mathematics.md): the relative "H1 error" on square meshes,
h = 2^-2 ... 2^-6, against the 2^-8 reference, and the observed orders. Our Table 1 gives, for
every stabilization and for three measures, the error, its ratio to the paper's error, the order
and its difference from the paper's order (5 significant digits):

- ``paper``: the paper's own measure |Pi_1^ref(I_ref u_h - u_ref)|_H1 / |Pi_1^ref u_ref|_H1
  (``vemkit.vem.norms.paper_error``), first; target: errors within 0.1 %, orders within 0.002;
- ``paper_gauss`` (when ``error_paper_gauss`` is in the file, config ``table1.gauss``): the same
  with the normal-compliance integral on Gamma_C by Gauss points per edge; same target;
- ``h1`` and ``h1_semi``: Pi_1 on each mesh, full H1 norm and H1 seminorm; target 10 % and 0.1.

Nothing is hidden: every option is listed, and the summary names the closest one and says
whether it meets its target.

The functions take a convergence Dataset (``vemkit.studies.convergence``) in memory or as read from disk
(undefined entries NaN, or masked integers -1).
"""

from __future__ import annotations

import csv
import io
import math

import numpy as np
import xarray as xr
import yaml

from vemkit.studies.paper import paper_value

ERROR_TARGET = 0.10  # |ratio - 1| <= 10 % (Pi_1 on each mesh)
ORDER_TARGET = 0.1  # |order - paper order| <= 0.1
PAPER_ERROR_TARGET = 0.001  # the paper's measure: |ratio - 1| <= 0.1 %
PAPER_ORDER_TARGET = 0.002
#: measure -> (error variable, order variable, label), the paper's measure first
NORMS = {
    "paper": ("error_paper", "order_paper", "paper's measure"),
    "paper_gauss": ("error_paper_gauss", "order_paper_gauss", "paper's measure, Gauss on Γ_C"),
    "h1": ("error_h1", "order", "H1"),
    "h1_semi": ("error_h1_semi", "order_h1_semi", "H1 semi"),
}
TARGETS = {
    "paper": (PAPER_ERROR_TARGET, PAPER_ORDER_TARGET),
    "paper_gauss": (PAPER_ERROR_TARGET, PAPER_ORDER_TARGET),
    "h1": (ERROR_TARGET, ORDER_TARGET),
    "h1_semi": (ERROR_TARGET, ORDER_TARGET),
}


def h_label(h: float, latex: bool = False) -> str:
    """``2^-3`` for h = 1/8 (``2^{-3}`` for LaTeX math mode), else the number."""
    k = -math.log2(h) if h > 0 else float("nan")
    if np.isfinite(k) and abs(k - round(k)) < 1e-9:
        return f"2^{{-{round(k)}}}" if latex else f"2^-{round(k)}"
    return f"{h:.4g}"


def _value(da: xr.DataArray) -> float:
    v = float(da.values)
    return v if np.isfinite(v) and v != -9999.0 else float("nan")


def _stabilizations(ds: xr.Dataset) -> list[str]:
    """The stabilizations of ``ds``, the scene's own (the default discretization) first."""
    stabs = [str(s) for s in ds["stabilization"].values]
    try:
        own = (yaml.safe_load(ds.attrs.get("scene", "")) or {})["discretization"]["stabilization"]
    except (yaml.YAMLError, KeyError, TypeError):
        own = None
    return sorted(stabs, key=lambda s: s != own)


def table1_rows(ds: xr.Dataset, family: str = "square") -> list[dict]:
    """Long-format rows: one per (norm, stabilization, h) of ``family``, with the paper's values."""
    rows = []
    sub = ds.sel(family=family)
    for norm, (err_key, order_key, _) in NORMS.items():
        if err_key not in ds:
            continue
        for stab in _stabilizations(ds):
            for h in ds["h"].values:
                cell = sub.sel(stabilization=stab, h=h)
                error = _value(cell[err_key])
                if not np.isfinite(error):
                    continue
                order = _value(cell[order_key])
                p_err, p_order = paper_value(float(h), "error"), paper_value(float(h), "order")
                rows.append(
                    {
                        "stabilization": stab,
                        "norm": norm,
                        "n": int(round(1 / float(h))),
                        "h": float(h),
                        "error": error,
                        "paper_error": p_err,
                        "ratio": error / p_err if p_err else None,
                        "order": order if np.isfinite(order) else None,
                        "paper_order": p_order,
                        "order_difference": (order - p_order) if (p_order is not None and np.isfinite(order)) else None,
                    }
                )
    return rows


def table1_summary(ds: xr.Dataset, family: str = "square") -> list[dict]:
    """Per (stabilization, norm): worst |ratio - 1|, worst |order - paper|, target met; best first."""
    groups = {}
    for r in table1_rows(ds, family):
        groups.setdefault((r["stabilization"], r["norm"]), []).append(r)
    out = []
    for (stab, norm), rows in groups.items():
        ratios = [abs(r["ratio"] - 1) for r in rows if r["ratio"] is not None]
        orders = [abs(r["order_difference"]) for r in rows if r["order_difference"] is not None]
        worst_ratio = max(ratios) if ratios else float("nan")
        worst_order = max(orders) if orders else float("nan")
        error_target, order_target = TARGETS[norm]
        out.append(
            {
                "stabilization": stab,
                "norm": norm,
                "compared": len(ratios),
                "max_error_deviation": worst_ratio,
                "max_order_deviation": worst_order,
                "meets_target": bool(ratios)
                and worst_ratio <= error_target
                and (not orders or worst_order <= order_target),
            }
        )
    out.sort(key=lambda s: s["max_error_deviation"] if np.isfinite(s["max_error_deviation"]) else np.inf)
    return out


def _fmt(v, kind: str) -> str:
    if v is None or (isinstance(v, float) and not np.isfinite(v)):
        return "–"
    if kind == "error":
        return f"{v:.4e}"
    if kind == "diff":
        return f"{v:+.5f}"
    return f"{v:#.5g}"  # ratio, order: 5 significant digits


def _grid(ds: xr.Dataset, family: str):
    """(h values, per (stab, norm) quantity lines) for the wide tables."""
    rows = table1_rows(ds, family)
    hs = sorted({r["h"] for r in rows}, reverse=True)
    lines = [
        ("paper", "Table 1", "error", [_fmt(paper_value(h, "error"), "error") for h in hs]),
        ("paper", "Table 1", "order", [_fmt(paper_value(h, "order"), "order") for h in hs]),
    ]
    stabs = list(dict.fromkeys(r["stabilization"] for r in rows))
    norms = list(NORMS)
    # the paper's measure first (each stabilization with its variants), then H1 and H1 semi
    groups = sorted(
        dict.fromkeys((r["norm"], r["stabilization"]) for r in rows),
        key=lambda g: (0 if g[0].startswith("paper") else norms.index(g[0]), stabs.index(g[1]), norms.index(g[0])),
    )
    for norm, stab in groups:
        norm_name = NORMS[norm][2]
        by_h = {r["h"]: r for r in rows if r["stabilization"] == stab and r["norm"] == norm}
        get = lambda key, kind: [_fmt(by_h[h][key], kind) if h in by_h else "–" for h in hs]  # noqa: E731, B023 - used in this iteration
        lines += [
            (stab, norm_name, "error", get("error", "error")),
            (stab, norm_name, "ratio to paper", get("ratio", "ratio")),
            (stab, norm_name, "order", get("order", "order")),
            (stab, norm_name, "order − paper", get("order_difference", "diff")),
        ]
    return hs, lines


def _summary_lines(ds, family) -> list[str]:
    summary = table1_summary(ds, family)
    out = []
    for s in summary:
        norm = NORMS[s["norm"]][2]
        error_target, order_target = TARGETS[s["norm"]]
        out.append(
            f"{s['stabilization']} / {norm}: max |ratio − 1| = {s['max_error_deviation']:.4%}, "
            f"max |order − paper| = {s['max_order_deviation']:.5f} over {s['compared']} levels"
            f" — target (≤ {error_target:.1%}, ± {order_target}) {'met' if s['meets_target'] else 'NOT met'}"
        )
    if summary:
        best = summary[0]
        out.append(f"closest to the paper: {best['stabilization']} with the {NORMS[best['norm']][2]}")
    return out


#: the paper's measure of the error of u_h, as the tables print it (module docstring: ``paper``)
PAPER_MEASURE = "|Π₁^ref(I_ref u_h − u_ref)|_H1 / |Π₁^ref u_ref|_H1"


def _markdown_table(caption: str, head: list, rows) -> list[str]:
    """The lines of a markdown table under its caption paragraph: the header, then one line per row."""
    return [caption, "", "| " + " | ".join(head) + " |", "|" + "---|" * len(head)] + [
        "| " + " | ".join(row) + " |" for row in rows
    ]


def table1_markdown(ds: xr.Dataset, family: str = "square") -> str:
    hs, lines = _grid(ds, family)
    head = ["stabilization", "measure", "quantity"] + [f"h = {h_label(h)}" for h in hs]
    caption = (
        "Table 1 — relative errors on square meshes against u_ref on h = 2^-8 of the same stabilization "
        f"(docs/reference/mathematics.md). paper's measure (the one the paper's Table 1 prints): {PAPER_MEASURE}, "
        "I_ref u_h the bilinear interpolant of u_h at the reference vertices, Π₁^ref the projection (3.8) on the "
        'reference cells, H1 seminorm; "Gauss on Γ_C": the same with the normal-compliance integral by Gauss points '
        "on each Γ_C edge instead of the nodal rule (config table1.gauss). H1 / H1 semi: ‖Π₁(u_h − u_ref)‖ / "
        "‖Π₁u_ref‖, Π₁ on each solution's own mesh, full H1 norm / H1 seminorm. ratio = ours / paper; order − paper "
        "= our order minus the paper's."
    )
    text = _markdown_table(caption, head, ([a, b, c, *vals] for a, b, c, vals in lines))
    text += ["", *[f"- {line}" for line in _summary_lines(ds, family)]]
    return "\n".join(text) + "\n"


def table1_csv(ds: xr.Dataset, family: str = "square") -> str:
    keys = [
        "stabilization",
        "norm",
        "n",
        "h",
        "error",
        "paper_error",
        "ratio",
        "order",
        "paper_order",
        "order_difference",
    ]  # norm: paper (the paper's measure), h1, h1_semi
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=keys, lineterminator="\n")
    writer.writeheader()
    for r in table1_rows(ds, family):
        writer.writerow({k: ("" if r[k] is None else (repr(r[k]) if isinstance(r[k], float) else r[k])) for k in keys})
    return buf.getvalue()


def _latex_escape(text: str) -> str:
    return (
        text.replace("\\", r"\textbackslash{}")
        .replace("_", r"\_")
        .replace("%", r"\%")
        .replace("&", r"\&")
        .replace("–", "--")
        .replace("−", "$-$")
    )


def table1_latex(ds: xr.Dataset, family: str = "square") -> str:
    hs, lines = _grid(ds, family)
    cols = "lll" + "r" * len(hs)
    out = [
        "% Table 1: relative errors on square meshes against the h = 2^-8 reference (docs/reference/mathematics.md);",
        "% ratio = ours / paper. Generated by vemkit.report.tables.",
        r"\begin{tabular}{" + cols + "}",
        r"\hline",
        " & ".join(["stabilization", "measure", "quantity"] + [f"$h = {h_label(h, True)}$" for h in hs]) + r" \\",
        r"\hline",
    ]
    previous = None
    for a, b, c, vals in lines:
        if previous is not None and (a, b) != previous:
            out.append(r"\hline")
        previous = (a, b)
        out.append(" & ".join(_latex_escape(x) for x in (a, b, c, *vals)) + r" \\")
    out += [r"\hline", r"\end{tabular}"]
    return "\n".join(out) + "\n"


# -- convergence tables (all families) -------------------------------------------------------------
def convergence_rows(ds: xr.Dataset) -> list[dict]:
    rows = []
    for fam in [str(f) for f in ds["family"].values]:
        for stab in [str(s) for s in ds["stabilization"].values]:
            for h in ds["h"].values:
                cell = ds.sel(family=fam, stabilization=stab, h=h)
                e1 = _value(cell["error_h1"])
                if not np.isfinite(e1):
                    continue
                order, order_semi = _value(cell["order"]), _value(cell["order_h1_semi"])
                paper = _value(cell["error_paper"]) if "error_paper" in ds else float("nan")
                order_paper = _value(cell["order_paper"]) if "order_paper" in ds else float("nan")
                rows.append(
                    {
                        "family": fam,
                        "stabilization": stab,
                        "n": int(round(1 / float(h))),
                        "h": float(h),
                        "error_h1": e1,
                        "order": order if np.isfinite(order) else None,
                        "error_h1_semi": _value(cell["error_h1_semi"]),
                        "order_h1_semi": order_semi if np.isfinite(order_semi) else None,
                        "error_paper": paper if np.isfinite(paper) else None,
                        "order_paper": order_paper if np.isfinite(order_paper) else None,
                        "n_dofs": int(_value(cell["n_dofs"])),
                        "iterations": int(_value(cell["iterations"])),
                        "wall_time": _value(cell["wall_time"]),
                    }
                )
    return rows


def convergence_csv(ds: xr.Dataset) -> str:
    rows = convergence_rows(ds)
    keys = [
        "family",
        "stabilization",
        "n",
        "h",
        "error_paper",
        "order_paper",
        "error_h1",
        "order",
        "error_h1_semi",
        "order_h1_semi",
        "n_dofs",
        "iterations",
        "wall_time",
    ]
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=keys, lineterminator="\n")
    writer.writeheader()
    for r in rows:
        writer.writerow({k: ("" if r[k] is None else (repr(r[k]) if isinstance(r[k], float) else r[k])) for k in keys})
    return buf.getvalue()


def _convergence_grid(ds: xr.Dataset):
    rows = convergence_rows(ds)
    hs = sorted({r["h"] for r in rows}, reverse=True)
    measures = [("paper", "error_paper", "order_paper")] if "error_paper" in ds else []
    measures.append(("H1", "error_h1", "order"))
    lines = []
    for key in dict.fromkeys((r["family"], r["stabilization"]) for r in rows):
        by_h = {r["h"]: r for r in rows if (r["family"], r["stabilization"]) == key}
        for label, err_key, order_key in measures:
            cells = []
            for h in hs:
                r = by_h.get(h)
                if r is None or r[err_key] is None:
                    cells.append("–")
                else:
                    order = "–" if r[order_key] is None else f"{r[order_key]:.3f}"
                    cells.append(f"{r[err_key]:.3e} ({order})")
            lines.append((*key, label, cells))
    return hs, lines


def convergence_markdown(ds: xr.Dataset) -> str:
    hs, lines = _convergence_grid(ds)
    head = ["family", "stabilization", "measure"] + [f"h = {h_label(h)}" for h in hs]
    caption = (
        "Convergence on every mesh family: relative errors against the square h = 2^-8 reference "
        "(docs/reference/mathematics.md) and, in parentheses, the observed order. paper: the paper's measure "
        f"{PAPER_MEASURE} (I_ref: bilinear on squares, Wachspress coordinates on convex cells, mean value "
        "coordinates on cells with hanging nodes); H1: ‖Π₁(u_h − u_ref)‖_H1 / ‖Π₁u_ref‖_H1 with Π₁ on each mesh, "
        "whose integral resolves the coarse cell boundaries of non-nested meshes to the reference mesh size."
    )
    text = _markdown_table(caption, head, ([f, s, m, *cells] for f, s, m, cells in lines))
    return "\n".join(text) + "\n"


def convergence_latex(ds: xr.Dataset) -> str:
    hs, lines = _convergence_grid(ds)
    out = [
        "% Convergence on every mesh family: relative errors (order), paper's measure and H1.",
        "% Generated by vemkit.report.tables.",
        r"\begin{tabular}{lll" + "r" * len(hs) + "}",
        r"\hline",
        " & ".join(["family", "stabilization", "measure"] + [f"$h = {h_label(h, True)}$" for h in hs]) + r" \\",
        r"\hline",
    ]
    out += [" & ".join(_latex_escape(x) for x in (f, s, m, *cells)) + r" \\" for f, s, m, cells in lines]
    out += [r"\hline", r"\end{tabular}"]
    return "\n".join(out) + "\n"
