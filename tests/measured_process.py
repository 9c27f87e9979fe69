"""One vemkit process through the real command line, with its own peak memory.

A child's ``ru_maxrss`` starts at the high-water mark of the process it was forked from (Linux
keeps the old image's mark across exec): a vemkit process started by pytest reported pytest's own
size (measured: 827 MiB for ``vemkit --version`` from a parent holding 800 MiB; 711-744 MiB in the
suite for a solve of 236 MiB alone). So a small launcher process stands between: it sets the
address-space limit if asked, spawns vemkit, waits for it (``os.wait4``: that child's own usage),
kills it at the timeout, and prints its peak. The launcher's own mark is a few MiB.
"""

import subprocess
import sys
import time
from pathlib import Path

_LAUNCHER = """
import os, resource, signal, sys
limit, timeout, out, err, *args = sys.argv[1:]
if int(limit):
    resource.setrlimit(resource.RLIMIT_AS, (int(limit), int(limit)))
actions = [(os.POSIX_SPAWN_OPEN, 1, out, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644),
           (os.POSIX_SPAWN_OPEN, 2, err, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)]
pid = os.posix_spawn(sys.executable, [sys.executable, "-m", "vemkit.cli", *args], os.environ, file_actions=actions)
signal.signal(signal.SIGALRM, lambda *_: os.kill(pid, signal.SIGKILL))
signal.alarm(int(float(timeout)) + 1)
_, status, usage = os.wait4(pid, 0)
print(usage.ru_maxrss)
sys.exit(os.waitstatus_to_exitcode(status))
"""


def run_vemkit(args, cwd: Path, *, address_space: int = 0, timeout: float = 300.0):
    """(exit status, stdout, stderr, seconds, peak resident bytes) of ``vemkit ARGS`` run in ``cwd``,
    its address space limited to ``address_space`` bytes (0: no limit)."""
    out, err = Path(cwd) / ".vemkit-out", Path(cwd) / ".vemkit-err"
    start = time.perf_counter()
    run = subprocess.run(
        [sys.executable, "-c", _LAUNCHER, str(address_space), str(timeout), str(out), str(err), *map(str, args)],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=timeout + 30,
    )
    seconds = time.perf_counter() - start
    peak = int(run.stdout.split()[-1]) * 1024 if run.stdout.split() else 0
    return run.returncode, out.read_text(), err.read_text(), seconds, peak
