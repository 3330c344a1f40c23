"""Remove pythonfmu 0.7's use-after-free at process exit from an FMU's Linux binary.

pythonfmu's binary keeps the Python interpreter state in a static
``std::shared_ptr<PyState> pyState`` and also registers a library destructor,
``onLibraryUnload``, that sets ``pyState = nullptr``. The binary holds
``STB_GNU_UNIQUE`` symbols, so the dynamic loader never unloads it on ``dlclose``;
both clean-ups therefore run at process exit, in this order: ``exit()`` first runs the
static destructor of ``pyState`` (it frees the control block), then ``_dl_fini`` runs
``onLibraryUnload``, which decrements and may dispose that freed control block again.
Valgrind shows the invalid read in every process that instantiated the FMU; about one
process in 30-50 aborts with glibc's "corrupted double-linked list".

The fix drops ``onLibraryUnload`` from the binary's ``.fini_array`` by shortening
``DT_FINI_ARRAYSZ`` (it is the array's last entry, and the array runs from last to
first). The static destructor alone then releases the interpreter state once, at the
same moment of exit as before. Nothing else in the binary changes.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

UNLOAD_SYMBOL = "_ZN12_GLOBAL__N_115onLibraryUnloadEv"

_PT_LOAD, _PT_DYNAMIC = 1, 2
_SHT_SYMTAB = 2
_DT_NULL, _DT_RELA, _DT_RELASZ, _DT_FINI_ARRAY, _DT_FINI_ARRAYSZ = 0, 7, 8, 26, 28
_R_X86_64_RELATIVE = 8


@dataclass(frozen=True)
class _Elf:
    """The parts of an ELF64 little-endian shared object this module reads."""

    data: bytes
    loads: list[tuple[int, int, int]]  # (vaddr, offset, filesz) of each PT_LOAD
    dynamic: dict[int, tuple[int, int]]  # d_tag -> (file offset of the entry, d_val)

    def offset_of(self, vaddr: int) -> int:
        """File offset of a virtual address inside a loaded segment."""
        for start, offset, size in self.loads:
            if start <= vaddr < start + size:
                return offset + vaddr - start
        raise ValueError(f"address {vaddr:#x} is in no loaded segment")


def _parse(data: bytes) -> _Elf:
    if data[:4] != b"\x7fELF" or data[4] != 2 or data[5] != 1:
        raise ValueError("not an ELF64 little-endian file")
    phoff = struct.unpack_from("<Q", data, 0x20)[0]
    phentsize, phnum = struct.unpack_from("<HH", data, 0x36)
    loads: list[tuple[int, int, int]] = []
    dyn_offset = dyn_size = 0
    for k in range(phnum):
        p_type, _, p_offset, p_vaddr, _, p_filesz = struct.unpack_from(
            "<IIQQQQ", data, phoff + k * phentsize
        )
        if p_type == _PT_LOAD:
            loads.append((p_vaddr, p_offset, p_filesz))
        elif p_type == _PT_DYNAMIC:
            dyn_offset, dyn_size = p_offset, p_filesz
    dynamic: dict[int, tuple[int, int]] = {}
    for at in range(dyn_offset, dyn_offset + dyn_size, 16):
        tag, value = struct.unpack_from("<qQ", data, at)
        if tag == _DT_NULL:
            break
        dynamic.setdefault(tag, (at, value))
    return _Elf(data, loads, dynamic)


def _symbol_address(data: bytes, name: str) -> int | None:
    """Value of a symbol in the static symbol table (.symtab), or None."""
    shoff = struct.unpack_from("<Q", data, 0x28)[0]
    shentsize, shnum = struct.unpack_from("<HH", data, 0x3A)
    if shoff == 0:
        return None
    sections = [
        struct.unpack_from("<IIQQQQIIQQ", data, shoff + k * shentsize) for k in range(shnum)
    ]
    wanted = name.encode()
    for _, sh_type, _, _, offset, size, link, _, _, entsize in sections:
        if sh_type != _SHT_SYMTAB:
            continue
        strings = sections[link][4]
        for at in range(offset, offset + size, entsize):
            st_name = struct.unpack_from("<I", data, at)[0]
            end = data.index(b"\0", strings + st_name)
            if data[strings + st_name : end] == wanted:
                return struct.unpack_from("<Q", data, at + 8)[0]
    return None


def fini_functions(data: bytes) -> list[int]:
    """Addresses the loader calls from ``.fini_array`` at unload, in array order.

    Each slot holds either a link-time address or, in a shared object, an
    ``R_X86_64_RELATIVE`` relocation whose addend is the address.
    """
    elf = _parse(data)
    if _DT_FINI_ARRAY not in elf.dynamic:
        return []
    start = elf.dynamic[_DT_FINI_ARRAY][1]
    count = elf.dynamic[_DT_FINI_ARRAYSZ][1] // 8
    relative: dict[int, int] = {}
    if _DT_RELA in elf.dynamic:
        rela = elf.offset_of(elf.dynamic[_DT_RELA][1])
        for at in range(rela, rela + elf.dynamic[_DT_RELASZ][1], 24):
            r_offset, r_info, r_addend = struct.unpack_from("<QQq", data, at)
            if r_info & 0xFFFFFFFF == _R_X86_64_RELATIVE:
                relative[r_offset] = r_addend
    slots = [start + 8 * k for k in range(count)]
    return [
        relative.get(slot, struct.unpack_from("<Q", data, elf.offset_of(slot))[0]) for slot in slots
    ]


def has_exit_bug(data: bytes) -> bool:
    """True when pythonfmu's ``onLibraryUnload`` is still called at unload."""
    if data[:4] != b"\x7fELF":
        return False
    address = _symbol_address(data, UNLOAD_SYMBOL)
    return address is not None and address in fini_functions(data)


def remove_exit_bug(data: bytes) -> bytes:
    """Return the binary with ``onLibraryUnload`` dropped from ``.fini_array``.

    A binary without the bug (already patched, or a pythonfmu that fixed it) comes back
    unchanged.

    Parameters
    ----------
    data : bytes
        A shared object (any file: one that is not ELF comes back unchanged).

    Returns
    -------
    bytes
        The patched binary, or ``data`` itself when there is nothing to patch.

    Raises
    ------
    ValueError
        The destructor is in ``.fini_array`` but not as its last entry, a layout this
        fix does not handle (a pythonfmu other than 0.7?).
    """
    if data[:4] != b"\x7fELF":
        return data
    address = _symbol_address(data, UNLOAD_SYMBOL)
    functions = fini_functions(data)
    if address is None or address not in functions:
        return data
    if functions[-1] != address:
        raise ValueError(
            f"{UNLOAD_SYMBOL} is not the last .fini_array entry; this pythonfmu binary "
            "has a layout arcosim.build.exit_fix does not know (pythonfmu 0.7 is supported)"
        )
    elf = _parse(data)
    at, size = elf.dynamic[_DT_FINI_ARRAYSZ]
    patched = bytearray(data)
    struct.pack_into("<Q", patched, at + 8, size - 8)
    return bytes(patched)
