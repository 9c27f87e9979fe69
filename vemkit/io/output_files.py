"""Output files that never destroy what the user had (issue 9).

- :func:`output_target` refuses, before any work, an output path that is an input (the scene, a
  mesh file), that exists and is not a regular file (a directory, a device such as ``/dev/full``,
  a FIFO, a socket), that is too long, or whose directory is missing, is a file or is not
  writable. A symbolic link to a regular file is followed: the file it points to is replaced.
- :func:`atomic_outputs` writes every output to a temporary file next to its target (same
  directory, so the rename is atomic), fsyncs it and renames it over the target only when every
  output was written; on any failure it removes only the temporary files it created. SIGINT and
  SIGTERM are deferred while the files are written and renamed (a signal raised inside the netCDF
  writer can leave a lock held and hang), and delivered right after, once the temporary files
  are gone. Two processes writing the same target each rename a complete file: one wins.
- :func:`exit_on_signals` (the command line) makes SIGINT/SIGTERM/SIGHUP end the process at once,
  exit status 128 + signal number, after removing the temporary files this process created
  (:data:`CREATED`); nothing else is touched.
"""

from __future__ import annotations

import os
import signal
import stat
import sys
import tempfile
import threading
from contextlib import contextmanager
from pathlib import Path

from vemkit.exceptions import OutputError

__all__ = ["CREATED", "atomic_outputs", "exit_on_signals", "output_target", "same_file"]

#: temporary files this process created and has not renamed yet (removed on a signal)
CREATED: set[str] = set()
#: targets this process has replaced (for the message on a signal)
WRITTEN: list[str] = []
HANDLED_SIGNALS = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP")
                        if hasattr(signal, name))
_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
          (stat.S_ISSOCK, "a socket"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"))


def _kind(mode: int) -> str:
    return next((name for test, name in _KINDS if test(mode)), "not a regular file")


def same_file(a, b) -> bool:
    """Whether paths ``a`` and ``b`` name the same file (links and hard links included)."""
    try:
        return os.path.samefile(a, b)
    except OSError:  # one does not exist (yet): compare the resolved names
        return os.path.realpath(a) == os.path.realpath(b)


def _limits(directory: str) -> tuple[int, int]:
    try:
        return os.pathconf(directory, "PC_NAME_MAX"), os.pathconf(directory, "PC_PATH_MAX")
    except (OSError, ValueError):
        return 255, 4096


def output_target(path, option: str = "-o", inputs=()) -> Path:
    """The file ``path`` names, checked for writing (see the module docstring); else OutputError."""
    text = os.fspath(path)
    where = f"{option} {text if len(text) <= 80 else text[:60] + '...' + text[-17:]}"
    if not text or text.endswith(os.sep) or "\0" in text:
        raise OutputError(f"{where}: give the path of a file, e.g. {option} out.nc", key=option)
    target = Path(os.path.realpath(text))  # follow links: replace what they point to
    name_max, path_max = _limits(str(target.parent) if target.parent.is_dir() else "/")
    if len(os.fsencode(str(target))) >= path_max or len(os.fsencode(target.name)) > name_max - 24:
        raise OutputError(f"{where}: the path is too long (at most {path_max - 1} bytes, a name "
                          f"at most {name_max - 24} bytes here); choose a shorter one", key=option)
    for source in inputs:
        if source is not None and same_file(source, target):
            raise OutputError(f"{where}: this is the input file {source}; write the output to "
                              "another path", key=option)
    try:
        mode = os.stat(target).st_mode
    except FileNotFoundError:
        mode = None
    except OSError as error:  # a path under a file (ENOTDIR), a loop, no permission
        raise OutputError(f"{where}: cannot use this path ({error.strerror}); choose another",
                          key=option) from None
    if mode is not None and not stat.S_ISREG(mode):
        raise OutputError(f"{where}: exists and is {_kind(mode)}; give the path of a regular "
                          "file", key=option)
    _check_directory(target.parent, where, option)
    return target


def _check_directory(directory: Path, where: str, option: str) -> None:
    try:
        mode = os.stat(directory).st_mode
    except FileNotFoundError:
        raise OutputError(f"{where}: the directory {directory} does not exist; create it first",
                          key=option) from None
    except OSError as error:
        raise OutputError(f"{where}: cannot use the directory {directory} ({error.strerror}); "
                          "choose another path", key=option) from None
    if not stat.S_ISDIR(mode):
        raise OutputError(f"{where}: {directory} is not a directory; choose another path",
                          key=option)
    if not os.access(directory, os.W_OK | os.X_OK):
        raise OutputError(f"{where}: the directory {directory} is not writable; choose another "
                          "path", key=option)


def _temporary_next_to(target: Path) -> Path:
    fd, name = tempfile.mkstemp(prefix=f".{target.name[:100]}.", suffix=".part", dir=target.parent)
    CREATED.add(name)
    os.close(fd)
    return Path(name)


def _discard(paths) -> None:
    for path in paths:
        if path is not None and str(path) in CREATED:
            try:
                os.unlink(path)
            except FileNotFoundError:
                pass
            CREATED.discard(str(path))


def _finish(temporary: Path) -> None:
    """fsync the written temporary file and give it the permissions a new file gets."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(temporary, 0o666 & ~umask)  # mkstemp makes 0600
    fd = os.open(temporary, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _fsync_directory(directory: Path) -> None:
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


@contextmanager
def _signals_deferred():
    """Record SIGINT/SIGTERM/SIGHUP inside the block; yields the list of those received."""
    received: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield received
        return
    previous = {s: signal.signal(s, lambda number, _frame: received.append(number))
                for s in HANDLED_SIGNALS}
    try:
        yield received
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)


@contextmanager
def atomic_outputs(*targets):
    """Temporary files for ``targets`` (None entries stay None); renamed over them on success.

    ``with atomic_outputs(out, vtu) as (tmp_out, tmp_vtu): write(tmp_out); write(tmp_vtu)``
    """
    targets = [None if t is None else Path(t) for t in targets]
    temporaries: list = []
    committed = False
    with _signals_deferred() as received:
        try:
            temporaries.extend(None if t is None else _temporary_next_to(t) for t in targets)
            yield temporaries
            if not received:
                pairs = [(tmp, t) for tmp, t in zip(temporaries, targets) if t is not None]
                for tmp, _ in pairs:
                    _finish(tmp)
                for tmp, target in pairs:
                    os.replace(tmp, target)
                    CREATED.discard(str(tmp))
                    WRITTEN.append(str(target))
                for directory in {target.parent for _, target in pairs}:
                    _fsync_directory(directory)
                committed = True
        finally:
            if not committed:
                _discard(temporaries)
    if received:  # deliver the deferred signal now that nothing is half written
        signal.raise_signal(received[0])


def _exit_now(number, _frame) -> None:
    _discard(list(CREATED))
    name = signal.Signals(number).name
    done = f"; wrote {', '.join(WRITTEN)} before it" if WRITTEN else "; no output written"
    try:
        os.write(2, f"vemkit: interrupted by {name}{done}\n".encode())
    except OSError:
        pass
    os._exit(128 + number)


@contextmanager
def exit_on_signals(restore: bool = True):
    """Inside the block (and after it, unless ``restore``), SIGINT/SIGTERM/SIGHUP remove this
    process's temporary files and exit with status 128 + the signal number."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {s: signal.signal(s, _exit_now) for s in HANDLED_SIGNALS}
    try:
        yield
    finally:
        sys.stderr.flush()
        for number, handler in previous.items() if restore else ():
            signal.signal(number, handler)
