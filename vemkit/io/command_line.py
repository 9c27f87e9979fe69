"""What the ``vemkit`` command shows while it works and says when a write fails.

:class:`ProgressLine` is a tqdm line on a terminal with the contact iterations (silent otherwise);
:func:`write_failures` turns a failing writer (a full disk, a vanished directory) into an
OutputError naming the outputs and saying truly what was written.
"""

from __future__ import annotations

import sys
from contextlib import contextmanager

from vemkit.exceptions import OutputError


class ProgressLine:
    """A tqdm line on a terminal showing the contact iterations; silent otherwise."""

    def __init__(self, enabled: bool, method: str):
        self.bar = None
        if enabled:
            from tqdm import tqdm

            self.bar = tqdm(desc=f"{method}", unit="it", leave=False, file=sys.stderr, dynamic_ncols=True)

    def __call__(self, iteration: int, info: dict | None = None):
        if self.bar is None:
            return
        self.bar.update(1)
        if info:
            self.bar.set_postfix({k: f"{v:.2e}" if isinstance(v, float) else v for k, v in info.items()}, refresh=False)

    def close(self):
        if self.bar is not None:
            self.bar.close()


@contextmanager
def write_failures(*outputs):
    """A failing writer is an OutputError naming the ``outputs`` (paths; None skipped) and saying
    truly what was written (paths shortened, the reason whole)."""
    try:
        yield
    except (OSError, RuntimeError) as error:
        from vemkit.io.output_files import WRITTEN, shown

        names = " and ".join(shown(p) for p in outputs if p)
        reason = (
            error.strerror
            if isinstance(error, OSError) and error.strerror
            else shown(" ".join(str(error).split()), 200)
        )
        done = f"only {', '.join(map(shown, WRITTEN))} was written" if WRITTEN else "nothing was written"
        raise OutputError(
            f"cannot write {names} ({reason}); {done}: check the disk space and permissions", key="-o"
        ) from None
