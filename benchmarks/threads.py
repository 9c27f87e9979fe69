"""Would a second thread speed up CG and its V-cycle? The finest level's memory-bound kernels on one
stiffness matrix, serial against a Numba ``prange`` twin on 1 and 2 threads (issue 22).

    .venv/bin/python benchmarks/threads.py [--n 708] [--family triangle|square] [--repeat 20]

Measures, on the paper scene's stiffness matrix K (structured triangles by default: n = 708 is the
1 005 362-DOF elasticity case of benchmarks/peers.py): the CSR product K x by scipy (serial) and by
the row-parallel kernels below (the same sums in the same order: the results are compared bit for
bit), with signed and with unsigned indices, each in float64 and in the V-cycle's float32; one
forward Gauss-Seidel sweep by pyamg; and a plain copy of as many bytes as K's values and column
indices (numpy), the memory traffic a product cannot go below. Every time is the best of
``--repeat`` (wall). Writes benchmarks/out/threads.{json,md}.
"""

from __future__ import annotations

import argparse

import numba
import numpy as np
import scipy.sparse as sp

from _common import MACHINE, best_of, paper_problem, write_report


@numba.njit(cache=True, parallel=True)
def row_parallel_product(indptr, indices, data, x, out):
    """out += A x, the rows split over the threads (scipy's csr_matvec sums, row by row)."""
    for i in numba.prange(out.shape[0]):
        s = out[i]
        for p in range(indptr[i], indptr[i + 1]):
            s += data[p] * x[indices[p]]
        out[i] = s


@numba.njit(cache=True, parallel=True)
def row_parallel_product_unsigned(indptr, indices, data, x, out):
    """The same sums with the positions and columns read as unsigned: Numba then drops its test of
    every signed index for wraparound (x[-1] is the last entry), which doubled the loop's time."""
    for i in numba.prange(out.shape[0]):
        s = out[i]
        p = np.uint64(indptr[i])
        end = np.uint64(indptr[i + 1])
        while p < end:
            s += data[p] * x[np.uint64(indices[p])]
            p += np.uint64(1)
        out[i] = s


KERNELS = {"numba": row_parallel_product, "numba_unsigned": row_parallel_product_unsigned}


def measure(K, repeat: int) -> dict:
    record = {}
    for precision in (np.float64, np.float32):
        record.update(measure_precision(K, precision, repeat))
    return record


def measure_precision(K, precision, repeat: int) -> dict:
    """The kernels on K's values in ``precision`` (keys suffixed with its name)."""
    from pyamg.relaxation.relaxation import gauss_seidel

    name = np.dtype(precision).name
    A = sp.csr_matrix((K.data.astype(precision), K.indices, K.indptr), shape=K.shape)
    x = np.random.default_rng(0).standard_normal(A.shape[0]).astype(precision)
    reference = A @ x
    record = {f"scipy_product_{name}_ms": 1e3 * best_of(lambda: A @ x, repeat)[0]}
    same_bits = []
    for kernel_name, kernel in KERNELS.items():
        for threads in (1, 2):
            numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
            out = np.zeros_like(x)
            kernel(A.indptr, A.indices, A.data, x, out)
            same_bits.append(bool(np.array_equal(out, reference)))
            record[f"{kernel_name}_product_{name}_{threads}_threads_ms"] = (
                1e3 * best_of(lambda kernel=kernel: kernel(A.indptr, A.indices, A.data, x, np.zeros_like(x)), repeat)[0]
            )
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    record[f"same_bits_{name}"] = all(same_bits)
    record[f"pyamg_gauss_seidel_{name}_ms"] = (
        1e3 * best_of(lambda: gauss_seidel(A, np.zeros_like(x), x, sweep="forward"), repeat)[0]
    )
    traffic = np.empty(A.data.nbytes + A.indices.nbytes, dtype=np.uint8)
    target = np.empty_like(traffic)
    record[f"copy_{name}_ms"] = 1e3 * best_of(lambda: np.copyto(target, traffic), repeat)[0]
    record[f"bytes_{name}"] = int(traffic.nbytes)
    return record


def report_lines(record: dict) -> list:
    lines = [
        "# One thread or two: the finest level's kernels (benchmarks/threads.py)",
        "",
        f"Machine: {MACHINE}, {numba.config.NUMBA_NUM_THREADS} Numba threads. "
        f"K: {record['dofs']:,} DOFs, {record['nnz']:,} entries ({record['family']}, n = {record['n']}). "
        "Best of the repeats, milliseconds.",
        "",
        "| values | scipy K x | Numba K x, 1 / 2 threads | Numba K x, unsigned indices, 1 / 2 threads "
        "| same bits | pyamg Gauss-Seidel | copy of values + indices (GB/s) |",
        "|---|---|---|---|---|---|---|",
    ]
    for name in ("float64", "float32"):
        rate = record[f"bytes_{name}"] / (record[f"copy_{name}_ms"] * 1e-3) / 1e9
        kernels = [
            " / ".join(f"{record[f'{kernel}_product_{name}_{t}_threads_ms']:.1f}" for t in (1, 2)) for kernel in KERNELS
        ]
        lines.append(
            f"| {name} | {record[f'scipy_product_{name}_ms']:.1f} | {kernels[0]} | {kernels[1]} "
            f"| {record[f'same_bits_{name}']} | {record[f'pyamg_gauss_seidel_{name}_ms']:.1f} "
            f"| {record[f'copy_{name}_ms']:.1f} ({rate:.1f}) |"
        )
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=708)
    parser.add_argument("--family", default="triangle", choices=["triangle", "square"])
    parser.add_argument("--repeat", type=int, default=20)
    args = parser.parse_args()
    problem, record = paper_problem(args.n, args.family)
    K = problem.stiffness.tocsr()
    record.update(measure(K, args.repeat))
    write_report("threads", record, report_lines(record))


if __name__ == "__main__":
    main()
