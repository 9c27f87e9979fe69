"""benchmarks/threads.py: its row-parallel product is scipy's CSR product to the last bit, on one and
on two threads, in float64 and float32 (the claim its report makes), on a small stiffness matrix."""

import sys
from pathlib import Path

import numpy as np

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.append(str(BENCHMARKS))  # appended: the benchmark scripts' names shadow nothing
import threads  # noqa: E402


def test_the_row_parallel_product_has_scipys_bits_and_the_report_its_numbers():
    problem, facts = threads.paper_problem(8)
    K = problem.stiffness.tocsr()
    record = threads.measure(K, repeat=1)
    assert record["same_bits_float64"] and record["same_bits_float32"]
    assert record["bytes_float64"] == K.nnz * (8 + K.indices.itemsize)
    assert all(np.isfinite(v) and v > 0 for k, v in record.items() if k.endswith("_ms"))
    lines = threads.report_lines(record | facts)
    assert sum(line.startswith("| float") for line in lines) == 2
