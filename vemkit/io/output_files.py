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
  (:data:`CREATED`); nothing else is touched. Under the command's supervisor
  (``vemkit.io.supervisor``) the worker ignores signals instead and reports its temporary files and
  the final write on a pipe (:data:`REPORT_FD`, :func:`_report`): the parent handles the signal.
"""

from __future__ import annotations

import os
import secrets
import signal
import stat
import sys
import threading
from contextlib import contextmanager
from pathlib import Path

from vemkit.config.safe_yaml import file_kind
from vemkit.exceptions import OutputError
from vemkit.io.temporary_names import temporary_name

__all__ = ["CREATED", "atomic_outputs", "deliver", "exit_on_signals", "output_target", "same_file", "shown"]

#: temporary files this process created and has not renamed yet (removed on a signal)
CREATED: set[str] = set()
#: targets this process has replaced (for the message on a signal)
WRITTEN: list[str] = []
#: in a worker under ``vemkit.io.supervisor``: the pipe to the parent (see :func:`_report`)
REPORT_FD: int | None = None
HANDLED_SIGNALS = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name))


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


def shown(path, limit: int = 80) -> str:
    """``path`` for a message: printable (bytes that are not UTF-8 as ``\\xff``, as a shell shows
    them) and at most ``limit`` characters (the middle cut), so a long path never crowds the reason
    out of the one-line error."""
    text = os.fspath(path)
    text = os.fsdecode(text) if isinstance(text, bytes) else text
    text = text.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
    text = "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)
    if len(text) <= limit:
        return text
    tail = max(20, min(len(os.path.basename(text)) + 1, limit - 23))  # the name whole if it fits
    return text[: limit - 3 - tail] + "..." + text[-tail:]


def output_target(path, option: str = "-o", inputs=()) -> Path:
    """The file ``path`` names, checked for writing (see the module docstring); else OutputError."""
    text = os.fspath(path)
    text = os.fsdecode(text) if isinstance(text, bytes) else text
    where = f"{option} {shown(text)}"
    if not text or text.endswith(os.sep) or "\0" in text:
        raise OutputError(f"{where}: give the path of a file, e.g. {option} out.nc", key=option)
    target = Path(os.path.realpath(text))  # follow links: replace what they point to
    name_max, path_max = _limits(str(target.parent) if target.parent.is_dir() else "/")
    # the temporary file beside it has a name of at most TEMPORARY_NAME_MAX bytes (temporary_name):
    # any name the file system takes is a valid output name; only its path may not get longer
    longer = max(0, len(temporary_name(target.name, "0" * 12)) - len(os.fsencode(target.name)))
    if len(os.fsencode(str(target))) >= path_max or len(os.fsencode(target.name)) > name_max:
        raise _too_long(where, option, path_max - 1 - longer, name_max)
    for source in inputs:
        if source is not None and same_file(source, target):
            raise OutputError(
                f"{where}: this is the input file {shown(source)}; write the output to another path", key=option
            )
    try:
        mode = os.stat(target).st_mode
    except FileNotFoundError:
        mode = None
    except OSError as error:  # a path under a file (ENOTDIR), a loop, no permission
        raise OutputError(f"{where}: cannot use this path ({error.strerror}); choose another", key=option) from None
    if mode is not None and not stat.S_ISREG(mode):
        raise OutputError(f"{where}: exists and is {file_kind(mode)}; give the path of a regular file", key=option)
    _check_directory(target.parent, where, option)
    if len(os.fsencode(str(target))) + longer >= path_max:  # its temporary file's path would be
        raise _too_long(where, option, path_max - 1 - longer, name_max)
    _check_replaceable(target, mode, where, option)
    return target


def _too_long(where: str, option: str, path_bytes: int, name_bytes: int) -> OutputError:
    return OutputError(
        f"{where}: the path is too long (at most {path_bytes} bytes, a name at most {name_bytes} bytes "
        "here); choose a shorter one",
        key=option,
    )


def _check_directory(directory: Path, where: str, option: str) -> None:
    folder = shown(directory)
    try:
        mode = os.stat(directory).st_mode
    except FileNotFoundError:
        raise OutputError(f"{where}: the directory {folder} does not exist; create it first", key=option) from None
    except OSError as error:
        raise OutputError(
            f"{where}: cannot use the directory {folder} ({error.strerror}); choose another path", key=option
        ) from None
    if not stat.S_ISDIR(mode):
        raise OutputError(f"{where}: {folder} is not a directory; choose another path", key=option)
    if not os.access(directory, os.W_OK | os.X_OK):
        raise OutputError(f"{where}: the directory {folder} is not writable; choose another path", key=option)
    flags = _inode_flags(directory)
    if flags & (FS_APPEND_FL | FS_IMMUTABLE_FL):
        kind = "append-only" if flags & FS_APPEND_FL else "immutable"
        raise OutputError(
            f"{where}: the directory {folder} is {kind} (chattr +{kind[0]}): a file "
            "made there could not be renamed into place nor removed; choose another "
            f"directory or lift it with chattr -{kind[0]}",
            key=option,
        )


#: Linux inode flags (``chattr``): a directory flagged so lets files be created in it but not
#: renamed or removed (+a), or not even created (+i)
FS_APPEND_FL, FS_IMMUTABLE_FL = 0x20, 0x10
_FS_IOC_GETFLAGS = 0x80086601


def _inode_flags(path) -> int:
    """The ``chattr`` flags of ``path``, 0 where the file system or the platform has none."""
    try:
        import fcntl
        import struct
    except ImportError:  # not a POSIX system
        return 0
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError:
        return 0
    try:
        return struct.unpack("l", fcntl.ioctl(fd, _FS_IOC_GETFLAGS, struct.pack("l", 0)))[0]
    except OSError:  # ENOTTY: the file system keeps no such flags
        return 0
    finally:
        os.close(fd)


def _check_replaceable(target: Path, mode, where: str, option: str) -> None:
    """An existing target that this process may not replace: flagged append-only or immutable, or
    owned by another user in a sticky directory such as /tmp (rename over it fails)."""
    if mode is None:
        return
    if _inode_flags(target) & (FS_APPEND_FL | FS_IMMUTABLE_FL):
        raise OutputError(
            f"{where}: the file is append-only or immutable (chattr); it cannot be replaced: choose another path",
            key=option,
        )
    parent = os.stat(target.parent)
    uid = os.geteuid() if hasattr(os, "geteuid") else None
    if (
        uid not in (None, 0)
        and parent.st_mode & stat.S_ISVTX
        and os.stat(target).st_uid != uid
        and parent.st_uid != uid
    ):
        raise OutputError(
            f"{where}: the file belongs to another user in a sticky directory; it "
            "cannot be replaced: choose another path",
            key=option,
        )


def _report(record: str) -> None:
    """Tell the supervising parent (``vemkit.io.supervisor``) what this worker does, if it has one:
    ``part NAME`` before a temporary file is made, ``done NAME`` once a target was replaced,
    ``hold`` / ``free`` around the final write (a signal then waits for the writer)."""
    if REPORT_FD is not None:
        os.write(REPORT_FD, (record + "\n").encode("utf-8", "surrogateescape"))


def _temporary_next_to(target: Path) -> Path:
    """A new empty :func:`temporary_name` next to ``target``."""
    while True:
        name = os.path.join(target.parent, temporary_name(target.name, secrets.token_hex(6)))
        _report(f"part {name}")  # before it exists: a kill in between leaves nothing behind
        CREATED.add(name)
        try:
            os.close(os.open(name, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
        except FileExistsError:
            CREATED.discard(name)
            continue
        except BaseException:  # made or not: removed if it is there (_discard), never left unlisted
            _discard([name])
            raise
        return Path(name)


def _writer_path(temporary: Path, keep: list) -> Path:
    """The name a writer library opens: ``temporary`` itself, or, when its directory's name is not
    UTF-8, the same file through ``/proc/self/fd/DIRFD/`` (an ASCII alias)."""
    try:
        os.fspath(temporary).encode("utf-8")
        return temporary
    except UnicodeEncodeError:
        if not os.path.isdir("/proc/self/fd"):
            raise OutputError(
                f"{shown(temporary.parent)}: the directory's name is not UTF-8, which the "
                "netCDF library cannot open here; choose another directory",
                key="-o",
            ) from None
        fd = os.open(temporary.parent, os.O_RDONLY)
        keep.append(fd)
        return Path(f"/proc/self/fd/{fd}/{temporary.name}")


def _discard(paths) -> list:
    """Remove the temporary files among ``paths`` this process made; returns (path, reason) of
    those that could not be removed (an append-only directory, a permission taken away)."""
    left = []
    for path in paths:
        if path is not None and str(path) in CREATED:
            try:
                os.unlink(path)
            except FileNotFoundError:
                pass
            except OSError as error:
                left.append((str(path), error.strerror or str(error)))
            CREATED.discard(str(path))
    return left


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
    previous = {s: signal.signal(s, lambda number, _frame: received.append(number)) for s in HANDLED_SIGNALS}
    _report("hold")  # a supervising parent now forwards signals instead of ending this process
    try:
        yield received
    finally:
        _report("free")  # before the handlers go: a signal the parent forwards until it reads this is kept
        for number, handler in previous.items():
            signal.signal(number, handler)


@contextmanager
def atomic_outputs(*targets):
    """Temporary files for ``targets`` (None entries stay None); renamed over them on success.

    ``with atomic_outputs(out, vtu) as (tmp_out, tmp_vtu): write(tmp_out); write(tmp_vtu)``
    A failure to replace a target or to remove a temporary file is an OutputError saying what was
    written and what was left.
    """
    targets = [None if t is None else Path(t) for t in targets]
    temporaries: list = []
    descriptors: list = []
    committed, failure = False, None
    with _signals_deferred() as received:
        try:
            temporaries.extend(None if t is None else _temporary_next_to(t) for t in targets)
            yield [None if t is None else _writer_path(t, descriptors) for t in temporaries]
            if not received:
                _commit([(tmp, t) for tmp, t in zip(temporaries, targets) if t is not None])
                committed = True
        except OSError as error:
            failure = error
            raise
        finally:
            for fd in descriptors:
                os.close(fd)
            left = [] if committed else _discard(temporaries)
            if left:
                _left_behind(left, failure)
    if received:  # deliver the deferred signal now that nothing is half written
        deliver(received[0])


def _commit(pairs) -> None:
    for tmp, _ in pairs:
        _finish(tmp)
    for tmp, target in pairs:
        os.replace(tmp, target)
        CREATED.discard(str(tmp))
        WRITTEN.append(str(target))
        _report(f"done {target}")
    for directory in {target.parent for _, target in pairs}:
        _fsync_directory(directory)


def _left_behind(left, failure) -> None:
    name, reason = left[0]
    written = f"wrote {', '.join(map(shown, WRITTEN))}" if WRITTEN else "nothing was written"
    cause = f" after {failure.strerror or failure}" if isinstance(failure, OSError) else ""
    raise OutputError(
        f"could not finish the output{cause}: {written}, and the temporary file "
        f"{shown(name)} could not be removed ({reason}); remove it by hand and check the "
        "directory's permissions and attributes (lsattr -d)",
        key="-o",
    )


def deliver(number: int) -> None:
    """Act on a signal that was held back: in a supervised worker exit at once (its handlers ignore
    signals: the parent handles them), else raise it again in this process."""
    if REPORT_FD is not None:
        _exit_now(number, None)
    signal.raise_signal(number)


def _exit_now(number, _frame) -> None:
    _discard(list(CREATED))
    name = signal.Signals(number).name
    done = f"; wrote {', '.join(map(shown, WRITTEN))} before it" if WRITTEN else "; no output written"
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
