"""Reading YAML a user wrote, safely: scene files and ``--set`` / ``--option`` values (issue 9).

- Plain data only: no anchors or aliases (``&a``, ``*a``: a few lines of nested aliases expand
  to billions of nodes), no explicit tags (``!!float``, ``!!python/...``), no merge keys.
- YAML 1.2 core schema scalars: ``1e-10`` and ``2e3`` are numbers (YAML 1.1 reads them as
  strings); ``1:20`` is a string (YAML 1.1 reads the sexagesimal 80); ``yes``/``no``/``on``/
  ``off`` are strings; ``true``/``false`` are booleans; ``0x1f`` and ``0o17`` are integers;
  ``1_000`` is a string; dates are strings.
- Duplicate keys are refused; nesting deeper than :data:`MAX_DEPTH` is refused.
- :func:`read_user_file` reads at most :data:`MAX_FILE_BYTES` from a regular file (never a
  directory, device or FIFO, which could block or never end).

Every problem is a one-line :class:`~vemkit.exceptions.SceneError` naming the file (and line).
"""

from __future__ import annotations

import os
import re
import stat

import yaml

from vemkit.exceptions import SceneError

__all__ = ["MAX_DEPTH", "MAX_FILE_BYTES", "MAX_INTEGER_DIGITS", "SceneDumper", "parse_yaml", "read_user_file"]

MAX_FILE_BYTES = 256 << 10  # 256 KiB: a scene is a few hundred bytes; 1 MiB of YAML takes ~8 s to read
MAX_DEPTH = 32  # nested mappings/lists; a scene nests 4 deep
MAX_INTEGER_DIGITS = 30  # longer integers are refused (no scene value needs them)

_INT = re.compile(r"^(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)$")
_FLOAT = re.compile(
    r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
    r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"
)
_BOOL = re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$")
_NULL = re.compile(r"^(?:~|null|Null|NULL|)$")
_TAG = "tag:yaml.org,2002:"


def _core_schema_resolvers() -> dict:
    """The YAML 1.2 core schema as PyYAML implicit resolvers: {first character: [(tag, regexp)]}."""
    table: dict = {}
    for tag, regexp, first in (
        ("bool", _BOOL, "tTfF"),
        ("int", _INT, "-+0123456789"),
        ("float", _FLOAT, "-+.0123456789"),
        ("null", _NULL, ["~", "n", "N", ""]),
    ):
        for character in first:
            table.setdefault(character, []).append((_TAG + tag, regexp))
    return table


class _Composer:
    """Mixin: refuse anchors, aliases and explicit tags, and bound the nesting depth."""

    _depth = 0

    def compose_node(self, parent, index):
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent) or getattr(event, "anchor", None) is not None:
            raise yaml.composer.ComposerError(
                None, None, "anchors and aliases (&name, *name) are not allowed; write the values out", event.start_mark
            )
        tag = getattr(event, "tag", None)
        if tag not in (None, "!"):
            raise yaml.composer.ComposerError(
                None, None, f"explicit tags ({tag}) are not allowed; write plain values", event.start_mark
            )
        self._depth += 1
        try:
            if self._depth > MAX_DEPTH:
                raise yaml.composer.ComposerError(
                    None,
                    None,
                    f"nested more than {MAX_DEPTH} levels deep; a scene nests a few levels",
                    event.start_mark,
                )
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


_SURROGATE = re.compile("[\ud800-\udfff]")
_PAIR = re.compile("([\ud800-\udbff])([\udc00-\udfff])")


def _joined_surrogates(text: str, node) -> str:
    """``text`` with each high-low surrogate pair joined into its character; a ConstructorError at
    ``node`` for a surrogate left over (a lone half)."""
    joined = _PAIR.sub(lambda m: chr(0x10000 + ((ord(m[1]) - 0xD800) << 10) + ord(m[2]) - 0xDC00), text)
    lone = _SURROGATE.search(joined)
    if lone is not None:
        raise yaml.constructor.ConstructorError(
            None,
            None,
            f"the string has a lone surrogate \\u{ord(lone[0]):04x} (half of a UTF-16 pair, not a "
            "character); write the character itself, its \\U00XXXXXX escape, or both halves of the pair",
            node.start_mark,
        )
    return joined


class UserLoader(_Composer, yaml.SafeLoader):
    """SafeLoader for user input: YAML 1.2 core scalars, no aliases/tags, no duplicate keys."""

    yaml_implicit_resolvers = _core_schema_resolvers()

    def construct_mapping(self, node, deep=False):
        seen = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            try:
                duplicate = key in seen
            except TypeError:  # unhashable (a list as a key): let SafeLoader report it
                break
            if duplicate:
                raise yaml.constructor.ConstructorError(None, None, f"duplicate key {key!r}", key_node.start_mark)
            seen.add(key)
        return super().construct_mapping(node, deep=deep)

    def construct_scalar(self, node):
        """The scalar's text; a UTF-16 surrogate pair written as two escapes ("\\ud83d\\ude00", as JSON
        writes a character beyond U+FFFF) is the one character it encodes; a lone surrogate (half
        of a pair, no character at all) is refused."""
        value = super().construct_scalar(node)
        if isinstance(value, str) and _SURROGATE.search(value):
            value = _joined_surrogates(value, node)
        return value

    def construct_core_int(self, node):
        text = self.construct_scalar(node)
        if len(text.lstrip("+-")) > MAX_INTEGER_DIGITS:
            raise yaml.constructor.ConstructorError(
                None, None, f"integer with {len(text)} digits; give at most {MAX_INTEGER_DIGITS}", node.start_mark
            )
        return int(text, 0) if text.startswith(("0o", "0x")) else int(text, 10)

    def construct_core_float(self, node):
        text = self.construct_scalar(node).lower()
        if text.endswith(("inf", "nan")):
            return float(text.replace(".", ""))
        return float(text)


UserLoader.add_constructor(_TAG + "int", UserLoader.construct_core_int)
UserLoader.add_constructor(_TAG + "float", UserLoader.construct_core_float)


class SceneDumper(yaml.SafeDumper):
    """SafeDumper that quotes every string a YAML 1.1 reader OR :class:`UserLoader` would not read
    as a string (``"1e3"``, ``"yes"``), so that its output reads back the same with both."""


for _character, _resolvers in _core_schema_resolvers().items():
    for _tag, _regexp in _resolvers:
        SceneDumper.add_implicit_resolver(_tag, _regexp, [_character] if _character else [""])


def parse_yaml(text: str, source: str):
    """The plain data of ``text``; a one-line SceneError naming ``source`` (and the line) if not."""
    try:
        return yaml.load(text, Loader=UserLoader)  # noqa: S506 - a SafeLoader subclass
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark or error.context_mark
        where = f"{source}:{mark.line + 1}" if mark is not None else source
        context = (
            f" ({error.context} at line {error.context_mark.line + 1})"
            if error.context and error.context_mark is not None and error.problem
            else ""
        )
        kind = (
            ""
            if isinstance(error, (yaml.composer.ComposerError, yaml.constructor.ConstructorError))
            else "YAML syntax error: "
        )
        raise SceneError(f"{where}: {kind}{error.problem or error.context}{context}", key=source) from None
    except yaml.YAMLError as error:
        raise SceneError(f"{source}: YAML syntax error: {error}", key=source) from None
    except RecursionError:
        raise SceneError(f"{source}: nested too deeply; a scene nests a few levels", key=source) from None


_KINDS = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISSOCK, "a socket"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
)


def file_kind(mode: int) -> str:
    """'a directory', 'a FIFO (named pipe)', ... for a non-regular file's ``st_mode``."""
    return next((name for test, name in _KINDS if test(mode)), "not a regular file")


def read_user_file(path, what: str = "scene file", max_bytes: int = MAX_FILE_BYTES) -> str:
    """The UTF-8 text of the regular file ``path``, at most ``max_bytes`` long (one-line errors)."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))  # a FIFO must not block
    except FileNotFoundError:
        raise SceneError(f"{path}: {what} not found", key=str(path)) from None
    except OSError as error:
        raise SceneError(f"{path}: cannot read the {what} ({error.strerror or error})", key=str(path)) from None
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise SceneError(
                f"{path}: cannot read the {what}: it is {file_kind(mode)}, not a regular file", key=str(path)
            )
        data = os.read(fd, max_bytes + 1)
        while len(data) <= max_bytes and (chunk := os.read(fd, max_bytes + 1 - len(data))):
            data += chunk
    except OSError as error:
        raise SceneError(f"{path}: cannot read the {what} ({error.strerror or error})", key=str(path)) from None
    finally:
        os.close(fd)
    if len(data) > max_bytes:
        raise SceneError(
            f"{path}: the {what} is larger than {max_bytes // 1024} KiB; a scene is a few hundred bytes", key=str(path)
        )
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise SceneError(f"{path}: not a UTF-8 text file", key=str(path)) from None
