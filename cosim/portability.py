"""What makes an FMU portable, checked on its files (standard library only).

Shared by the build (:mod:`arcosim.build.portable`, which refuses to ship an FMU
that fails them) and by ``arcosim validate`` (:mod:`arcosim.host.validate`):

- the Python code of an FMU lives in one package named ``arcosim_<identifier>_<digest>``
  (:func:`bundle_name`), which no host or other build can have imported;
- bundled modules import nothing by absolute name but the standard library
  (:func:`import_problems`);
- no Linux binary names an absolute path or a libpython in its NEEDED, RPATH or
  RUNPATH entries (:func:`dynamic_entries`).
"""

from __future__ import annotations

import ast
import re
import struct
import sys
import zipfile
from collections.abc import Mapping
from pathlib import Path

#: Hex digits of the source digest in a bundle's name.
DIGEST_LENGTH = 10
BUNDLE_PATTERN = re.compile(rf"arcosim_[A-Za-z_][A-Za-z0-9_]*_[0-9a-f]{{{DIGEST_LENGTH}}}")


def bundle_name(identifier: str, digest: str) -> str:
    """The one top-level package an FMU's Python code lives in.

    Examples
    --------
    >>> bundle_name("ReactionTorqueObserver_n3", "0123456789abcdef")
    'arcosim_ReactionTorqueObserver_n3_0123456789'
    """
    return f"arcosim_{identifier}_{digest[:DIGEST_LENGTH]}"


def import_problems(sources: Mapping[str, str]) -> list[str]:
    """Absolute imports, in bundled modules, of anything but the standard library."""
    stdlib = set(sys.stdlib_module_names) | {"__future__"}
    problems = []
    for path, text in sources.items():
        if not path.endswith(".py"):
            continue
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.Import):
                modules = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                modules = [node.module]
            else:
                continue
            for name in modules:
                if name.split(".")[0] not in stdlib:
                    problems.append(
                        f"{path}:{node.lineno} imports {name!r} by absolute name (the host's "
                        "copy would run, not the FMU's)"
                    )
    return problems


_DT_NEEDED, _DT_STRTAB, _DT_RPATH, _DT_RUNPATH = 1, 5, 15, 29


def dynamic_entries(data: bytes) -> dict[str, list[str]]:
    """NEEDED, RPATH and RUNPATH strings of an ELF64 little-endian shared object."""
    if data[:4] != b"\x7fELF" or data[4] != 2 or data[5] != 1:
        raise ValueError("not an ELF64 little-endian file")
    phoff = struct.unpack_from("<Q", data, 0x20)[0]
    phentsize, phnum = struct.unpack_from("<HH", data, 0x36)
    loads, dynamic = [], None
    for k in range(phnum):
        p_type, _, p_offset, p_vaddr, _, p_filesz = struct.unpack_from(
            "<IIQQQQ", data, phoff + k * phentsize
        )
        if p_type == 1:
            loads.append((p_vaddr, p_offset, p_filesz))
        elif p_type == 2:
            dynamic = (p_offset, p_filesz)
    if dynamic is None:
        return {"NEEDED": [], "RPATH": [], "RUNPATH": []}
    entries = []
    for at in range(dynamic[0], dynamic[0] + dynamic[1], 16):
        tag, value = struct.unpack_from("<qQ", data, at)
        if tag == 0:
            break
        entries.append((tag, value))
    strtab = next(v for t, v in entries if t == _DT_STRTAB)
    base = next(off + strtab - va for va, off, size in loads if va <= strtab < va + size)

    def string(offset: int) -> str:
        end = data.index(b"\0", base + offset)
        return data[base + offset : end].decode()

    kinds = {_DT_NEEDED: "NEEDED", _DT_RPATH: "RPATH", _DT_RUNPATH: "RUNPATH"}
    found: dict[str, list[str]] = {"NEEDED": [], "RPATH": [], "RUNPATH": []}
    for tag, value in entries:
        if tag in kinds:
            found[kinds[tag]].append(string(value))
    return found


def portability_problems(fmu: Path) -> list[str]:
    """What would tie the FMU to the machine that built it, or let a host's packages
    shadow its own: absolute or libpython entries in a Linux binary's NEEDED, RPATH or
    RUNPATH; Python code outside one uniquely named bundle; absolute imports of
    anything but the standard library."""
    with zipfile.ZipFile(fmu) as z:
        names = z.namelist()
        problems = [
            problem
            for name in names
            if name.startswith("binaries/linux64/") and name.endswith(".so")
            for problem in binary_problems(name, z.read(name))
        ]
        python = [n for n in names if n.startswith("resources/") and n.endswith(".py")]
        if python:
            problems += _bundle_problems(z, python)
    return problems


def binary_problems(name: str, data: bytes) -> list[str]:
    """What ties one Linux binary to the machine that built it: a NEEDED entry with a
    path or naming a libpython, an RPATH or RUNPATH part that is not ``$ORIGIN``-relative.

    Parameters
    ----------
    name : str
        The binary's name in the FMU, for the messages.
    data : bytes
        The binary (an ELF64 little-endian shared object).

    Returns
    -------
    list of str
        One line per problem (empty when none).
    """
    entries = dynamic_entries(data)
    problems = []
    for needed in entries["NEEDED"]:
        if "/" in needed or needed.startswith("libpython"):
            problems.append(f"{name}: NEEDED {needed} ties it to one Python installation")
    for kind in ("RPATH", "RUNPATH"):
        for value in entries[kind]:
            for part in value.split(":"):
                if part and not part.startswith("$ORIGIN"):
                    problems.append(f"{name}: {kind} {part} is an absolute path")
    return problems


def _bundle_problems(z: zipfile.ZipFile, python: list[str]) -> list[str]:
    """What lets a host's packages shadow the FMU's own Python code (``python``, its
    files under ``resources/``): no ``slavemodule.txt``, a slave module outside one
    uniquely named bundle, code outside the bundle, absolute imports."""
    if "resources/slavemodule.txt" not in z.namelist():
        return ["resources/slavemodule.txt is missing"]
    module = z.read("resources/slavemodule.txt").decode().strip()
    bundle = module.split(".")[0]
    problems = []
    if not BUNDLE_PATTERN.fullmatch(bundle):
        problems.append(
            f"resources/slavemodule.txt names {module!r}: not in a bundle named "
            "arcosim_<identifier>_<digest> (a host could have imported it)"
        )
    allowed = {"resources/slavemodule.txt", f"resources/{module}.py"}
    for name in python:
        if name not in allowed and not name.startswith(f"resources/{bundle}/"):
            problems.append(f"{name}: Python code outside the bundle {bundle}/")
    sources = {n: z.read(n).decode("utf-8") for n in python}
    return problems + import_problems(sources)
