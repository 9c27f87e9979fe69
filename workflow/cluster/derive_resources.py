"""Per-rule SLURM resources from the measured benchmarks (the `benchmark:` TSVs of the rules).

    .venv/bin/python workflow/cluster/derive_resources.py [RESULTS_DIR ...]            print a table
    .venv/bin/python workflow/cluster/derive_resources.py --write [RESULTS_DIR ...]    and update the profile

Each rule's benchmark file pattern is read from its `benchmark:` in workflow/rules/*.smk; every TSV
under RESULTS_DIR/benchmarks (default: results/) is assigned to its rule. Per rule, from the largest
peak memory (max_rss, MB), the longest wall time (s) and CPU use (cpu_time / s) measured:

    mem_mb        = MEM_FACTOR x peak memory + JOBSTEP_MB, at least MEM_FLOOR, rounded up to 100 MB
    runtime       = TIME_FACTOR x longest wall time, at least TIME_FLOOR minutes, rounded up to 5 min
    cpus_per_task = the rule's `threads:` if more than 1, else the CPU use rounded up (1 for vemkit)

Safety factors: memory x 2 (a denser mesh or another family than the measured one), time x 3 (a slower
or busier node than the measuring one; a job over its time is killed, one over its memory too).
JOBSTEP_MB: inside a SLURM job a `snakemake` process runs the rule's script, and SLURM counts both; the
benchmark TSV has the script alone (make cluster-test: sacct's MaxRSS exceeds it by 70-160 MB).
Only the configuration that was run is measured: scale a sweep part's runtime with its points (README,
"Scale on paper"). `--write` replaces the block between the BEGIN/END markers of
workflow/profiles/slurm/config.yaml; rules without a benchmark keep the profile's default-resources.
"""

from __future__ import annotations

import argparse
import csv
import math
import re
import sys
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]
RULES_DIR = ROOT / "workflow" / "rules"
PROFILE = ROOT / "workflow" / "profiles" / "slurm" / "config.yaml"
MEM_FACTOR, MEM_FLOOR, JOBSTEP_MB = 2.0, 1000, 300  # MB
TIME_FACTOR, TIME_FLOOR = 3.0, 10  # minutes
BEGIN = "  # BEGIN derived by workflow/cluster/derive_resources.py"
END = "  # END derived"


def benchmark_patterns(rules_dir: Path = RULES_DIR) -> dict[str, tuple[re.Pattern, int]]:
    """rule -> (regex of its benchmark path below results/, its `threads:`), from the .smk files."""
    patterns = {}
    for smk in sorted(rules_dir.glob("*.smk")):
        rule, threads, expect_benchmark = None, 1, False
        for line in smk.read_text().splitlines():
            if match := re.match(r"\s*(?:local)?rule (\w+):", line):
                rule, threads = match.group(1), 1
            elif match := re.match(r"\s*threads:\s*(\d+)", line):
                threads = int(match.group(1))
                if rule in patterns:
                    patterns[rule] = (patterns[rule][0], threads)
            elif re.match(r"\s*benchmark:\s*$", line):
                expect_benchmark = True
            elif expect_benchmark and line.strip():
                path = line.strip().strip("\"'").removeprefix("results/")
                regex = re.sub(r"\\\{\w+\\\}", "[^/]+", re.escape(path))
                patterns[rule] = (re.compile(regex + "$"), threads)
                expect_benchmark = False
    return patterns


def local_rules(rules_dir: Path = RULES_DIR, snakefile: Path = ROOT / "Snakefile") -> set[str]:
    """The rules named under a `localrules:` (they run where snakemake runs: no SLURM resources)."""
    names = set()
    for path in [snakefile, *sorted(rules_dir.glob("*.smk"))]:
        for block in re.findall(r"^\s*localrules:\s*\n((?:[ \t]+\w+,?[ \t]*\n?)+)", path.read_text(), re.M):
            names |= set(re.findall(r"\w+", block))
    return names


def read_benchmarks(results_dirs: list[Path], patterns) -> dict[str, list[dict]]:
    """rule -> the rows (s, max_rss, cpu_time as floats) of every benchmark TSV of that rule."""
    rows: dict[str, list[dict]] = {}
    for results in results_dirs:
        for tsv in sorted((results / "benchmarks").rglob("*.tsv")):
            name = str(tsv.relative_to(results))
            rules = [rule for rule, (regex, _) in patterns.items() if regex.search(name)]
            if len(rules) != 1:
                print(f"{name}: matches rules {rules or 'none'}; skipped", file=sys.stderr)
                continue
            with open(tsv) as handle:
                for row in csv.DictReader(handle, delimiter="\t"):
                    rows.setdefault(rules[0], []).append(
                        {k: _number(row.get(k)) for k in ("s", "max_rss", "cpu_time")} | {"file": name}
                    )
    return rows


def _number(text) -> float:
    try:
        return float(text)
    except (TypeError, ValueError):  # "NA" or missing
        return 0.0


def _round_up(value: float, step: int) -> int:
    return int(math.ceil(value / step) * step)


def derive(rows: list[dict], threads: int) -> dict:
    """The resources of one rule from its benchmark rows (see the module docstring)."""
    peak_mb = max(r["max_rss"] for r in rows)
    longest_s = max(r["s"] for r in rows)
    cpu_use = max((r["cpu_time"] / r["s"] for r in rows if r["s"] > 0), default=1.0)
    return {
        "mem_mb": max(MEM_FLOOR, _round_up(MEM_FACTOR * peak_mb + JOBSTEP_MB, 100)),
        "runtime": max(TIME_FLOOR, _round_up(TIME_FACTOR * longest_s / 60, 5)),
        "cpus_per_task": threads if threads > 1 else max(1, math.ceil(cpu_use - 0.2)),
        "measured": f"{len(rows)} run{'s' * (len(rows) != 1)}: peak {peak_mb:.0f} MB, longest {longest_s:.0f} s, "
        f"CPU use {cpu_use:.2f}",
    }


def profile_block(derived: dict[str, dict]) -> str:
    """The set-resources entries, between the markers."""
    lines = [BEGIN + f" (memory x {MEM_FACTOR:g} + {JOBSTEP_MB} MB, time x {TIME_FACTOR:g}; see its docstring)"]
    for rule, res in sorted(derived.items()):
        lines += [
            f"  {rule + ':':<18}# {res['measured']}",
            f"    mem_mb: {res['mem_mb']}",
            f"    runtime: {res['runtime']}",
            f"    cpus_per_task: {res['cpus_per_task']}",
        ]
    return "\n".join(lines + [END])


def write_profile(derived: dict[str, dict], profile: Path = PROFILE):
    """Replace the block; a rule of the old block without a benchmark now keeps its old values."""
    text = profile.read_text()
    old = yaml.safe_load(text).get("set-resources") or {}
    derived = {
        **{
            rule: {**res, "measured": "kept: no benchmark in the results given"}
            for rule, res in old.items()
            if rule not in derived
        },
        **derived,
    }
    start, stop = text.find(BEGIN), text.find(END)
    if start < 0 or stop < start:
        raise SystemExit(f"{profile}: no '{BEGIN.strip()}' ... '{END.strip()}' block under set-resources")
    stop = text.index("\n", stop) if "\n" in text[stop:] else len(text)
    profile.write_text(text[:start] + profile_block(derived) + text[stop:])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description="SLURM resources per rule from the benchmark TSVs")
    parser.add_argument(
        "results",
        nargs="*",
        type=Path,
        default=[ROOT / "results"],
        help="results directories with a benchmarks/ folder (default: results/)",
    )
    parser.add_argument("--write", action="store_true", help=f"update the set-resources block of {PROFILE}")
    args = parser.parse_args(argv)
    patterns = benchmark_patterns()
    rows = read_benchmarks(args.results, patterns)
    if not rows:
        print("no benchmark TSVs found: run the workflow first (every heavy rule writes one)", file=sys.stderr)
        return 1
    local = local_rules()
    derived = {rule: derive(r, patterns[rule][1]) for rule, r in rows.items() if rule not in local}
    print(f"| rule | measured | mem_mb | runtime (min) | cpus_per_task |\n|---|---|---|---|---|")
    for rule, res in sorted(derived.items()):
        print(f"| {rule} | {res['measured']} | {res['mem_mb']} | {res['runtime']} | {res['cpus_per_task']} |")
    if args.write:
        write_profile(derived)
        print(f"updated {PROFILE}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
