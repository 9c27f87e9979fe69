"""Shared by the workflow scripts: the job's log file, and the level n of a wildcard."""

from __future__ import annotations

import contextlib
import sys
import time
import traceback


@contextlib.contextmanager
def logged(smk):
    """Send the job's prints and any traceback to its log file (``log:`` of the rule)."""
    path = smk.log[0] if smk.log else None
    stream = open(path, "w", encoding="utf-8") if path else sys.stderr  # noqa: SIM115
    t0 = time.perf_counter()
    try:
        with contextlib.redirect_stdout(stream), contextlib.redirect_stderr(stream):
            print(f"rule {smk.rule}: wildcards {dict(smk.wildcards)}", flush=True)
            try:
                yield
            except BaseException:
                traceback.print_exc()
                raise
            finally:
                print(f"elapsed {time.perf_counter() - t0:.3f} s", flush=True)
    finally:
        if path:
            stream.close()


def level(text):
    """The n of a file name as a number: 16 -> 16, 22.627417 -> 22.627417."""
    value = float(text)
    return int(value) if value.is_integer() else value
