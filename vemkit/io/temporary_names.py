"""The name of a temporary file written next to its target (:mod:`vemkit.io.output_files`, the
workflow's records): ASCII, and short enough for any target name the file system takes."""

from __future__ import annotations

import re

__all__ = ["TEMPORARY_NAME_MAX", "temporary_name"]

#: the longest name :func:`temporary_name` gives (a stem of 100 characters, the token, the dots):
#: far below NAME_MAX (255 on Linux), so a target name up to NAME_MAX bytes has its temporary file
TEMPORARY_STEM = 100
TEMPORARY_NAME_MAX = 1 + TEMPORARY_STEM + 1 + 12 + len(".part")


def temporary_name(name: str, token: str) -> str:
    """``.NAME.TOKEN.part`` for a target called ``name``: ASCII (the netCDF library encodes names as
    UTF-8: a target name that is not UTF-8 must not reach it) and at most TEMPORARY_NAME_MAX bytes
    for a 12-character token, whatever the length of ``name`` (the stem is its first 100 characters)."""
    return f".{re.sub(r'[^A-Za-z0-9._-]', '_', name[:TEMPORARY_STEM])}.{token}.part"
