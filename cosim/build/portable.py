"""Turn the FMU pythonfmu built into one that runs on any Linux machine with a CPython ≥ 3.9.

pythonfmu's output ties the FMU to nothing but it also loads nowhere but in a Python
host, and it bundles its packages under their own top-level names (``fmukit``,
``flexchain``, ``pythonfmu``), so a host that imported packages of those names runs
them instead of the FMU's. :func:`make_portable` rewrites the zip:

``binaries/linux64/<modelIdentifier>.so``
    the trampoline (``arcosim/build/native/fmu_trampoline.c``, compiled here per build): no
    libpython, no RUNPATH; finds a CPython at ``fmi2Instantiate`` and forwards to
``binaries/linux64/pythonfmu-export.so``
    pythonfmu's own binary (the core), with its exit-time use-after-free removed
    (:mod:`arcosim.build.exit_fix`);
``binaries/win64/*``
    pythonfmu's Windows binary, unchanged (untested);
``resources/slavemodule.txt``
    ``<bundle>.slave``: the module pythonfmu's C++ imports (``PyImport_ImportModule``);
``resources/<bundle>.slave.py``
    the text pythonfmu's loader compiles and runs in that module's namespace to find
    the class (a file name with a dot: it can never be imported);
``resources/<bundle>/``
    ``__init__.py``, ``slave.py`` (the generated class), and every bundled package,
    pythonfmu's runtime modules included, all importing each other relatively.

``<bundle>`` is ``arcosim_<modelIdentifier>_<first 10 hex digits of the source digest>``:
no host and no other build can have imported a module of that name.
"""

from __future__ import annotations

import subprocess
import tempfile
import zipfile
from collections.abc import Mapping
from pathlib import Path
from xml.etree import ElementTree

from arcosim.build.cplant import compiler as c_compiler
from arcosim.build.exit_fix import remove_exit_bug
from arcosim.errors import BuildError
from arcosim.portability import bundle_name, import_problems

TRAMPOLINE = Path(__file__).parent / "native" / "fmu_trampoline.c"
CORE = "pythonfmu-export.so"  # not lib*: nothing to confuse with a libpython
#: pythonfmu modules an FMU never imports (its CLI and builders).
PYTHONFMU_UNUSED = frozenset({"__main__.py", "csvbuilder.py", "deploy.py"})

# pythonfmu 0.7's loader (findClass) runs this text in the namespace of the module
# named in slavemodule.txt and then releases one reference to that namespace it never
# took, once per fmi2Instantiate. Taking one reference here, each time it runs, cancels
# the stray release exactly. The second line hands the loader the class, already
# defined by the module itself (it looks for a class whose MRO holds Fmi2Slave).
_LOADER_TEXT = """\
# Read and run by pythonfmu's loader in the namespace of {module} (see arcosim/build/portable.py);
# never imported.
import ctypes as _ctypes

_ctypes.pythonapi.Py_IncRef(_ctypes.py_object(globals()))
{cls} = {cls}
"""


def make_portable(
    fmu: Path,
    *,
    packages: Mapping[str, Path],
    base: str,
    n: int,
    version: str,
    digest: str,
    headers: Path,
) -> str:
    """Rewrite pythonfmu's FMU in place into the portable layout (module docstring).

    Parameters
    ----------
    fmu : Path
        The FMU pythonfmu built (its modelDescription.xml and binaries are kept).
    packages : mapping of str to Path
        Name → folder of every package to bundle (``fmukit``, ``flexchain``,
        ``arobserver``); pythonfmu's runtime is added to them.
    base : str
        ``package.module:Class`` of the slave class, e.g.
        ``arobserver.fmu:ReactionTorqueObserver``.
    n : int
        Number of load masses (the generated class's ``n_masses``, a count).
    version : str
        Project version written into the generated class.
    digest : str
        The source digest (hex) the bundle's name is derived from.
    headers : Path
        Folder of the FMI 2.0 headers (``fmi2Functions.h``) for the trampoline.

    Returns
    -------
    str
        The bundle's package name.

    Raises
    ------
    BuildError
        A bundled module imports something other than the standard library by
        absolute name, or the C compiler failed (its output included).
    """
    with zipfile.ZipFile(fmu) as z:
        members = {info.filename: z.read(info) for info in z.infolist()}
    root = ElementTree.fromstring(members["modelDescription.xml"])
    identifier = root.find("CoSimulation").get("modelIdentifier")
    guid = root.get("guid")
    bundle = bundle_name(identifier, digest)
    kept = {
        name: data
        for name, data in members.items()
        if not name.startswith("resources/") and not name.startswith("binaries/linux64/")
    }
    sources = _bundle_sources(packages, base, identifier, n, version, bundle)
    problems = import_problems(sources)
    if problems:
        raise BuildError("the FMU would import code it does not ship:\n  " + "\n  ".join(problems))
    for name, text in sources.items():
        kept[f"resources/{name}"] = text.encode("utf-8")
    cls_name = identifier
    kept["resources/slavemodule.txt"] = f"{bundle}.slave".encode()
    kept[f"resources/{bundle}.slave.py"] = _LOADER_TEXT.format(
        module=f"{bundle}.slave", cls=cls_name
    ).encode()
    core = members[f"binaries/linux64/{identifier}.so"]
    kept[f"binaries/linux64/{CORE}"] = remove_exit_bug(core)
    kept[f"binaries/linux64/{identifier}.so"] = compile_trampoline(
        identifier=identifier, guid=guid, bundle=bundle, n=n, headers=headers
    )
    partial = fmu.with_suffix(".fmu.part")
    with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as z:
        for name in sorted(kept):
            info = zipfile.ZipInfo(name, date_time=(2020, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            mode = 0o755 if name.endswith((".so", ".dll")) else 0o644
            info.external_attr = (0o100000 | mode) << 16  # a regular file, readable by all
            z.writestr(info, kept[name])
    partial.replace(fmu)
    return bundle


def compile_trampoline(*, identifier: str, guid: str, bundle: str, n: int, headers: Path) -> bytes:
    """The trampoline for one build, compiled with the plant's C compiler (``$CC``, else
    ``cc`` or ``gcc``: :func:`arcosim.build.cplant.compiler`)."""
    compiler = c_compiler()
    with tempfile.TemporaryDirectory(prefix="arcosim_trampoline_") as tmp:
        out = Path(tmp) / f"{identifier}.so"
        command = [
            compiler,
            "-std=c99",
            "-O2",
            "-fPIC",
            "-shared",
            "-fvisibility=hidden",
            "-Wall",
            "-Wextra",
            f"-I{headers}",
            f'-DARCOSIM_IDENTIFIER="{identifier}"',
            f'-DARCOSIM_GUID="{guid}"',
            f'-DARCOSIM_BUILD="{bundle}"',
            f"-DARCOSIM_N={n}",
            f'-DARCOSIM_CORE="{CORE}"',
            str(TRAMPOLINE),
            "-o",
            str(out),
            "-Wl,--as-needed",
            "-ldl",
            "-lpthread",
        ]
        result = subprocess.run(command, capture_output=True, text=True)
        if result.returncode != 0:
            raise BuildError(
                f"compiling the FMU's binary failed:\n  {' '.join(command)}\n{result.stderr}"
            )
        return out.read_bytes()


def _bundle_sources(
    packages: Mapping[str, Path],
    base: str,
    identifier: str,
    n: int,
    version: str,
    bundle: str,
) -> dict[str, str]:
    """Every text file of the bundle, by path under ``resources/``."""
    import pythonfmu

    folders = dict(packages)
    folders["pythonfmu"] = Path(pythonfmu.__file__).parent
    files: dict[str, str] = {}
    for package, folder in folders.items():
        vendored = package == "pythonfmu"  # its top-level modules, as its own builder does
        for path in sorted(folder.glob("*.py") if vendored else folder.rglob("*.py")):
            relative = path.relative_to(folder)
            if "__pycache__" in relative.parts:
                continue
            if vendored and str(relative) in PYTHONFMU_UNUSED:
                continue
            text = path.read_text(encoding="utf-8")
            files[f"{bundle}/{package}/{relative.as_posix()}"] = text
    module, cls = base.split(":")
    files[f"{bundle}/__init__.py"] = (
        f'"""The Python code of the FMU {identifier}, built by arcosim {version}: every module\n'
        'it runs, under this one name (see arcosim/build/portable.py)."""\n'
    )
    files[f"{bundle}/slave.py"] = (
        f'"""The FMU\'s slave class: {cls} for n = {n} load masses."""\n\n'
        f"from .{module} import {cls}\n\n\n" + slave_class(identifier, cls, n, version)
    )
    return files


def slave_class(identifier: str, base: str, n: int, version: str) -> str:
    """Source of the FMU's slave class ``identifier``: ``base`` for ``n`` load masses,
    built by arcosim ``version``."""
    return f"class {identifier}({base}):\n    n_masses = {n}\n    project_version = {version!r}\n"
