"""The command's supervisor: SIGINT/SIGTERM/SIGHUP end a run within a second, even inside a long
Numba kernel (issue 18, item 8).

Why a second process: CPython runs a signal handler only between bytecodes of the main thread, so a
compiled kernel that runs for seconds (assembly, a sparse factorisation, an AMG set-up) holds the
handler back until it returns. Running the work in a thread instead would need every long kernel
compiled ``nogil=True``; a process needs no change to the numerical code. So the console command
(``vemkit``, ``python -m vemkit.cli``) forks before any heavy import, and

- the **worker** (the child) does the work with those signals ignored; it announces on a pipe every
  temporary file before it makes it (``part NAME``), every target it replaced (``done NAME``), and
  the final write/rename (``hold`` ... ``free``, while ``vemkit.io.output_files`` holds signals back);
- the **parent** only waits. On a signal it drains the pipe; inside ``hold`` it forwards the signal
  (the worker delivers it right after the write, as before: the netCDF writer is never interrupted
  inside a lock) and exits with the worker's status; otherwise it kills the worker (SIGKILL), removes
  the announced temporary files that were not renamed, prints ``vemkit: interrupted by SIGINT; no
  output written`` (or what was written) and exits 128 + the signal number.

The worker dies with the parent (``PR_SET_PDEATHSIG`` on Linux). In-process calls
(``vemkit.cli.main(argv)``, the tests' harnesses) keep the handlers of ``output_files``.
"""

from __future__ import annotations

import os
import select
import signal
import sys

from vemkit.io import output_files

SIGNALS = output_files.HANDLED_SIGNALS


def supervised(work) -> int:
    """Run ``work()`` (returns an exit status) in a forked worker and return the status this
    process must exit with; without ``os.fork`` run it here."""
    if not hasattr(os, "fork"):
        return work()
    read_fd, write_fd = os.pipe()
    supervisor = _Supervisor(read_fd)
    old_mask = signal.pthread_sigmask(signal.SIG_BLOCK, SIGNALS)  # no signal between fork and pid
    for number in SIGNALS:
        signal.signal(number, supervisor.on_signal)
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:
        os.close(read_fd)
        _worker(work, write_fd, old_mask)
    os.close(write_fd)
    supervisor.pid = pid
    signal.pthread_sigmask(signal.SIG_SETMASK, old_mask)
    return supervisor.wait()


def _worker(work, write_fd: int, old_mask) -> None:
    """The child: signals ignored (the parent handles them), then the work; never returns."""
    status = 70
    try:
        for number in SIGNALS:
            signal.signal(number, signal.SIG_IGN)
        signal.pthread_sigmask(signal.SIG_SETMASK, old_mask)
        _die_with_parent()
        output_files.REPORT_FD = write_fd
        status = work()
    except SystemExit as done:  # --help, --version: argparse ends the work with a status
        status = done.code if isinstance(done.code, int) else (0 if done.code is None else 2)
        if not isinstance(done.code, (int, type(None))):
            print(done.code, file=sys.stderr)
    except BaseException as error:  # noqa: BLE001 - work() reports its own failures; this is a bug
        print(f"vemkit: error: internal error ({type(error).__name__}: {error}); please report", file=sys.stderr)
    finally:
        try:
            sys.stdout.flush()
            sys.stderr.flush()
        finally:
            os._exit(status)


def _die_with_parent() -> None:
    parent = os.getppid()
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):  # not Linux: the parent still kills the worker on a signal
        pass
    if os.getppid() != parent:  # the parent died before prctl
        os._exit(128 + signal.SIGKILL)


class _Supervisor:
    """The parent's view of the worker, from its pipe records."""

    def __init__(self, read_fd: int):
        self.fd, self.pid, self.pending = read_fd, None, b""
        self.parts: dict[str, None] = {}
        self.done: list[str] = []
        self.holding = False
        self.forwarded: int | None = None
        os.set_blocking(read_fd, False)

    def drain(self) -> bool:
        """Read the worker's records so far; False once the worker closed its end (it ended)."""
        open_end = True
        while True:
            try:
                chunk = os.read(self.fd, 65536)
            except BlockingIOError:
                break
            if not chunk:
                open_end = False
                break
            self.pending += chunk
        *lines, self.pending = self.pending.split(b"\n")
        for line in lines:
            kind, _, name = line.decode("utf-8", "surrogateescape").partition(" ")
            if kind == "part":
                self.parts[name] = None
            elif kind == "done":
                self.done.append(name)
                self.parts = {p: None for p in self.parts if os.path.exists(p)}
            else:
                self.holding = kind == "hold"
        return open_end

    def _drain_masked(self) -> bool:
        """:meth:`drain` with the handled signals blocked: ``on_signal`` (which drains too) never
        runs in the middle of a drain. Without the mask a signal landing after a drain had taken
        the records ``hold``, ``part NAME`` off the pipe and before it stored them made
        ``on_signal`` see neither: it killed the worker as outside the final write and removed
        the temporary files it knew of, and the worker's fresh, announced ``.part`` stayed (issue
        33: 1 SIGINT in 24 sent as the ``.part`` appeared). A signal blocked here is delivered
        when the mask is lifted, the records stored."""
        previous = signal.pthread_sigmask(signal.SIG_BLOCK, SIGNALS)
        try:
            return self.drain()
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, previous)

    def on_signal(self, number, _frame) -> None:
        previous = signal.pthread_sigmask(signal.SIG_BLOCK, SIGNALS)  # a second signal waits for this one
        self.drain()
        if self.holding:  # the final write: the worker delivers it right after
            self.forwarded = number
            os.kill(self.pid, number)
            signal.pthread_sigmask(signal.SIG_SETMASK, previous)
            return
        try:
            os.kill(self.pid, signal.SIGKILL)
            os.waitpid(self.pid, 0)
        except (ProcessLookupError, ChildProcessError):
            pass
        self.drain()
        self._finish(number, f"interrupted by {signal.Signals(number).name}")

    def _finish(self, number: int, what: str) -> None:
        """Remove the worker's temporary files, one line, exit 128 + ``number``."""
        for name in self.parts:
            try:
                os.unlink(name)
            except OSError:
                pass
        done = (
            f"; wrote {', '.join(map(output_files.shown, self.done))} before it" if self.done else "; no output written"
        )
        try:
            os.write(2, f"vemkit: {what}{done}\n".encode("utf-8", "backslashreplace"))
        finally:
            os._exit(128 + number)

    def wait(self) -> int:
        """The worker's exit status, once it ended by itself (its records read as they come, so
        that it never blocks on a full pipe)."""
        while self._drain_masked():
            select.select([self.fd], [], [])  # a signal interrupts it: on_signal runs at once
        while True:
            try:
                _, status = os.waitpid(self.pid, 0)
                break
            except ChildProcessError:  # pragma: no cover - reaped by the signal handler, which exits
                return 70
        self._drain_masked()
        if os.WIFSIGNALED(status):  # killed from outside (the out-of-memory killer, kill -9)
            number = os.WTERMSIG(status)
            self._finish(
                number,
                f"error: the run was ended by {signal.Signals(number).name} from outside "
                "vemkit (e.g. the system ran out of memory)",
            )
        code = os.waitstatus_to_exitcode(status)
        if code == 0 and self.forwarded is not None:  # the signal came as the worker finished
            self._finish(self.forwarded, f"interrupted by {signal.Signals(self.forwarded).name}")
        return code
