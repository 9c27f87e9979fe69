"""Table 1 of the paper next to ours (Markdown, CSV, LaTeX), and the convergence tables.

``PAPER_TABLE1`` holds the paper's numbers (SPEC §5): the relative "H1 error" on square meshes,
h = 2^-2 ... 2^-6, against the 2^-8 reference, and the observed orders. Our Table 1 gives, for
every stabilization and for both norms (the full H1 norm, which the paper names, and the H1
seminorm), the error, its ratio to the paper's error, the order and its difference from the
paper's order. Nothing is hidden: every option is listed, and the summary names the closest one
and says whether it meets the target (errors within 10 %, orders within 0.1).

The functions take a convergence Dataset (``vemkit.studies.convergence``) in memory or as read from disk
(undefined entries NaN, or masked integers -1).
"""

from __future__ import annotations

import csv
import io
import math

import numpy as np
import xarray as xr

from vemkit.studies.paper import PAPER_TABLE1, paper_value

ERROR_TARGET = 0.10  # |ratio - 1| <= 10 %
ORDER_TARGET = 0.1  # |order - paper order| <= 0.1
NORMS = {"h1": ("error_h1", "order", "H1"), "h1_semi": ("error_h1_semi", "order_h1_semi", "H1 semi")}


def h_label(h: float, latex: bool = False) -> str:
    """``2^-3`` for h = 1/8 (``2^{-3}`` for LaTeX math mode), else the number."""
    k = -math.log2(h) if h > 0 else float("nan")
    if np.isfinite(k) and abs(k - round(k)) < 1e-9:
        return f"2^{{-{round(k)}}}" if latex else f"2^-{round(k)}"
    return f"{h:.4g}"


def _value(da: xr.DataArray) -> float:
    v = float(da.values)
    return v if np.isfinite(v) and v != -9999.0 else float("nan")


def table1_rows(ds: xr.Dataset, family: str = "square") -> list[dict]:
    """Long-format rows: one per (stabilization, norm, h) of ``family``, with the paper's values."""
    rows = []
    sub = ds.sel(family=family)
    for stab in [str(s) for s in ds["stabilization"].values]:
        for norm, (err_key, order_key, _) in NORMS.items():
            for h in ds["h"].values:
                cell = sub.sel(stabilization=stab, h=h)
                error = _value(cell[err_key])
                if not np.isfinite(error):
                    continue
                order = _value(cell[order_key])
                p_err, p_order = paper_value(float(h), "error"), paper_value(float(h), "order")
                rows.append({
                    "stabilization": stab, "norm": norm, "n": int(round(1 / float(h))), "h": float(h),
                    "error": error, "paper_error": p_err,
                    "ratio": error / p_err if p_err else None,
                    "order": order if np.isfinite(order) else None, "paper_order": p_order,
                    "order_difference": (order - p_order) if (p_order is not None and np.isfinite(order)) else None,
                })
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
        out.append({
            "stabilization": stab, "norm": norm, "compared": len(ratios),
            "max_error_deviation": worst_ratio, "max_order_deviation": worst_order,
            "meets_target": bool(ratios) and worst_ratio <= ERROR_TARGET and
            (not orders or worst_order <= ORDER_TARGET),
        })
    out.sort(key=lambda s: (s["max_error_deviation"] if np.isfinite(s["max_error_deviation"]) else np.inf))
    return out


def _fmt(v, kind: str) -> str:
    if v is None or (isinstance(v, float) and not np.isfinite(v)):
        return "–"
    if kind == "error":
        return f"{v:.4e}"
    if kind == "ratio":
        return f"{v:.3f}"
    if kind == "diff":
        return f"{v:+.3f}"
    return f"{v:.4f}"


def _grid(ds: xr.Dataset, family: str):
    """(h values, per (stab, norm) quantity lines) for the wide tables."""
    rows = table1_rows(ds, family)
    hs = sorted({r["h"] for r in rows}, reverse=True)
    lines = [("paper", "H1", "error", [_fmt(paper_value(h, "error"), "error") for h in hs]),
             ("paper", "H1", "order", [_fmt(paper_value(h, "order"), "order") for h in hs])]
    for stab in dict.fromkeys(r["stabilization"] for r in rows):
        for norm, (_, _, norm_name) in NORMS.items():
            by_h = {r["h"]: r for r in rows if r["stabilization"] == stab and r["norm"] == norm}
            get = lambda key, kind: [_fmt(by_h[h][key], kind) if h in by_h else "–" for h in hs]  # noqa: E731
            lines += [(stab, norm_name, "error", get("error", "error")),
                      (stab, norm_name, "ratio to paper", get("ratio", "ratio")),
                      (stab, norm_name, "order", get("order", "order")),
                      (stab, norm_name, "order − paper", get("order_difference", "diff"))]
    return hs, lines


def _summary_lines(ds, family) -> list[str]:
    summary = table1_summary(ds, family)
    out = []
    for s in summary:
        norm = NORMS[s["norm"]][2]
        out.append(f"{s['stabilization']} / {norm}: max |ratio − 1| = {s['max_error_deviation']:.3f}, "
                   f"max |order − paper| = {s['max_order_deviation']:.3f} over {s['compared']} levels"
                   f" — target (≤ {ERROR_TARGET:.0%}, ± {ORDER_TARGET}) {'met' if s['meets_target'] else 'NOT met'}")
    if summary:
        best = summary[0]
        out.append(f"closest to the paper: {best['stabilization']} in the {NORMS[best['norm']][2]} norm")
    return out


def table1_markdown(ds: xr.Dataset, family: str = "square") -> str:
    hs, lines = _grid(ds, family)
    head = ["stabilization", "norm", "quantity"] + [f"h = {h_label(h)}" for h in hs]
    text = [
        "Table 1 — relative errors ‖Π₁(u_h − u_ref)‖ / ‖Π₁u_ref‖ on square meshes, u_ref on h = 2^-8 of the "
        "same stabilization (SPEC §5). The paper reports the H1 norm; both the full H1 norm and the H1 "
        "seminorm are given. ratio = ours / paper; order − paper = our order minus the paper's.",
        "",
        "| " + " | ".join(head) + " |",
        "|" + "---|" * len(head),
    ]
    text += ["| " + " | ".join([a, b, c, *vals]) + " |" for a, b, c, vals in lines]
    text += ["", *[f"- {line}" for line in _summary_lines(ds, family)]]
    return "\n".join(text) + "\n"


def table1_csv(ds: xr.Dataset, family: str = "square") -> str:
    keys = ["stabilization", "norm", "n", "h", "error", "paper_error", "ratio", "order", "paper_order",
            "order_difference"]
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=keys, lineterminator="\n")
    writer.writeheader()
    for r in table1_rows(ds, family):
        writer.writerow({k: ("" if r[k] is None else (repr(r[k]) if isinstance(r[k], float) else r[k])) for k in keys})
    return buf.getvalue()


def _latex_escape(text: str) -> str:
    return (text.replace("\\", r"\textbackslash{}").replace("_", r"\_").replace("%", r"\%")
            .replace("&", r"\&").replace("–", "--").replace("−", "$-$"))


def table1_latex(ds: xr.Dataset, family: str = "square") -> str:
    hs, lines = _grid(ds, family)
    cols = "lll" + "r" * len(hs)
    out = [
        "% Table 1: relative errors on square meshes against the h = 2^-8 reference (SPEC 5);",
        "% ratio = ours / paper. Generated by vemkit.report.tables.",
        r"\begin{tabular}{" + cols + "}",
        r"\hline",
        " & ".join(["stabilization", "norm", "quantity"] + [f"$h = {h_label(h, True)}$" for h in hs]) + r" \\",
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
                rows.append({
                    "family": fam, "stabilization": stab, "n": int(round(1 / float(h))), "h": float(h),
                    "error_h1": e1, "order": order if np.isfinite(order) else None,
                    "error_h1_semi": _value(cell["error_h1_semi"]),
                    "order_h1_semi": order_semi if np.isfinite(order_semi) else None,
                    "n_dofs": int(_value(cell["n_dofs"])), "iterations": int(_value(cell["iterations"])),
                    "wall_time": _value(cell["wall_time"]),
                })
    return rows


def convergence_csv(ds: xr.Dataset) -> str:
    rows = convergence_rows(ds)
    keys = ["family", "stabilization", "n", "h", "error_h1", "order", "error_h1_semi", "order_h1_semi",
            "n_dofs", "iterations", "wall_time"]
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=keys, lineterminator="\n")
    writer.writeheader()
    for r in rows:
        writer.writerow({k: ("" if r[k] is None else (repr(r[k]) if isinstance(r[k], float) else r[k])) for k in keys})
    return buf.getvalue()


def _convergence_grid(ds: xr.Dataset):
    rows = convergence_rows(ds)
    hs = sorted({r["h"] for r in rows}, reverse=True)
    lines = []
    for key in dict.fromkeys((r["family"], r["stabilization"]) for r in rows):
        by_h = {r["h"]: r for r in rows if (r["family"], r["stabilization"]) == key}
        cells = []
        for h in hs:
            r = by_h.get(h)
            cells.append("–" if r is None else f"{r['error_h1']:.3e} ({_fmt(r['order'], 'order')[:5]})")
        lines.append((*key, cells))
    return hs, lines


def convergence_markdown(ds: xr.Dataset) -> str:
    hs, lines = _convergence_grid(ds)
    head = ["family", "stabilization"] + [f"h = {h_label(h)}" for h in hs]
    text = ["Convergence on every mesh family: relative full H1 error against the square h = 2^-8 reference "
            "(SPEC §5) and, in parentheses, the observed order. On non-nested meshes the error integral "
            "resolves coarse cell boundaries to the reference mesh size.", "",
            "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    text += ["| " + " | ".join([f, s, *cells]) + " |" for f, s, cells in lines]
    return "\n".join(text) + "\n"


def convergence_latex(ds: xr.Dataset) -> str:
    hs, lines = _convergence_grid(ds)
    out = ["% Convergence on every mesh family: relative H1 error (order). Generated by vemkit.report.tables.",
           r"\begin{tabular}{ll" + "r" * len(hs) + "}", r"\hline",
           " & ".join(["family", "stabilization"] + [f"$h = {h_label(h, True)}$" for h in hs]) + r" \\",
           r"\hline"]
    out += [" & ".join(_latex_escape(x) for x in (f, s, *cells)) + r" \\" for f, s, cells in lines]
    out += [r"\hline", r"\end{tabular}"]
    return "\n".join(out) + "\n"
