"""Build the plant FMU from C: ``plant_models/motorchain_c/`` compiled with the system
C compiler against the FMI 2.0 headers fmpy ships.

The interface is the Python plant's (:class:`arcosim.plant.motorchain.fmu.MotorChainPlant`, kept as
the reference): its variable list generates the model description (through
:mod:`arcosim.fmu.fmukit.model_description`, as every FMU of the project) and a C header of
names, types, causalities, start values and value references, so both cannot
drift apart. The FMU has no Python in it: it runs in any FMI host with nothing
installed, and a step costs about a microsecond instead of a hundred.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
import zipfile
from pathlib import Path
from xml.etree.ElementTree import SubElement, tostring

from arcosim.build.cache import plant_package_dir
from arcosim.build.recipes import PLANT
from arcosim.errors import BuildError
from arcosim.version import __version__

SOURCES = ("physics.c", "fmu.c")
HEADERS = (
    "physics.h",
    "fmi_shell.h",
    "matrix_exp.h",
    "friction_events.h",
    "sensor_noise.h",
)
#: ISO C99, no GNU extensions: the sources also build with MSVC or any C99 compiler,
#: against the FMI 2.0 (2014) headers as well as 2.0.1-2.0.4 (tests/test_cplant_sources.py).
CFLAGS = (
    "-O2",
    "-std=c99",
    "-pedantic",
    "-fPIC",
    "-shared",
    "-fvisibility=hidden",
    "-Wall",
    "-Wextra",
)

_TYPES = {"Real": "T_REAL", "Integer": "T_INTEGER", "Boolean": "T_BOOLEAN", "String": "T_STRING"}
_CAUSALITIES = {"parameter": "C_PARAMETER", "input": "C_INPUT", "output": "C_OUTPUT"}


def source_dir() -> Path:
    """Folder of the plant's C sources (package data of :mod:`arcosim.plant`)."""
    return plant_package_dir() / "motorchain_c"


def envelope_header() -> Path:
    """The state envelope every arcosim FMU shares (shipped in the plant's sources/)."""
    return Path(__file__).parent / "native" / "fmu_envelope.h"


def compiler() -> str:
    """The C compiler: ``$CC``, else ``cc`` or ``gcc`` on PATH."""
    for name in (os.environ.get("CC"), "cc", "gcc"):
        if name and shutil.which(name):
            return name
    raise BuildError(
        "no C compiler found to build the plant FMU: install one (Debian: "
        "`apt-get install gcc`) or name it in the CC environment variable"
    )


def fmi_headers() -> Path:
    """Folder of ``fmi2Functions.h`` as shipped by fmpy."""
    import fmpy

    folder = Path(fmpy.__file__).parent / "c-code"
    if not (folder / "fmi2Functions.h").is_file():
        raise BuildError(f"fmpy's FMI 2.0 headers are missing from {folder}; reinstall fmpy")
    return folder


def plant_class(n: int):
    """The reference plant class with ``n`` load masses and this project's version."""
    from arcosim.plant.motorchain.fmu import MotorChainPlant

    return type(
        PLANT.identifier(n),
        (MotorChainPlant,),
        {"n_masses": n, "project_version": __version__},
    )


def plant_variables(n: int):
    """Every variable of the plant with n masses, in value-reference order."""
    from arcosim.fmu.fmukit.slave import TRACE_FILE

    return [*plant_class(n).declare(), TRACE_FILE]


def model_description_xml(identifier: str, n: int) -> bytes:
    """The C plant's modelDescription.xml (same interface as the reference)."""
    from arcosim.fmu.fmukit.model_description import ModelInfo, model_description

    cls = plant_class(n)
    info = ModelInfo(identifier, cls.model_text, __version__, cls.experiment)
    options = {
        "needsExecutionTool": "false",
        "canGetAndSetFMUstate": "true",
        "canSerializeFMUstate": "true",
    }
    root = model_description(info, plant_variables(n), options)
    files = SubElement(root.find("CoSimulation"), "SourceFiles")
    for name in SOURCES:
        SubElement(files, "File", {"name": name})
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + tostring(root, encoding="utf-8")


def sources_digest(n: int) -> str:
    """First 10 hex digits of the SHA-256 of the plant's C sources and n: the build
    field of its serialized states' identity (a state from other sources is refused)."""
    import hashlib

    digest = hashlib.sha256(f"n={n}".encode())
    for name in (*SOURCES, *HEADERS):
        digest.update((source_dir() / name).read_bytes())
    digest.update(envelope_header().read_bytes())
    return digest.hexdigest()[:10]


def variables_header(n: int, guid: str) -> str:
    """C header: the variable table, ``VR_<name>`` macros, the GUID and fmukit's
    limits (:mod:`arcosim.fmu.fmukit.checks`), so that C and Python cannot drift apart."""
    return variables_table(
        plant_variables(n),
        PLANT.identifier(n),
        sources_digest(n),
        guid,
        f"motorchain.fmu.MotorChainPlant (n = {n})",
    )


def variables_table(variables: list, identifier: str, build: str, guid: str, origin: str) -> str:
    """The generated ``plant_variables.h`` of a C plant (this one or the flexible link's).

    Parameters
    ----------
    variables : list of Variable
        Every variable, in value-reference order.
    identifier : str
        The model identifier.
    build : str
        The digest of the plant's sources (the state envelope's build field).
    guid : str
        The model description's GUID.
    origin : str
        Where the variable list comes from, for the header's first line.

    Returns
    -------
    str
        The header's text.
    """
    from arcosim.fmu.fmukit import checks

    lines = [
        f"/* Generated by arcosim {__version__} from {origin}. */",
        "#ifndef PLANT_VARIABLES_H",
        "#define PLANT_VARIABLES_H",
        "/* The numbers every FMU computes in (fmukit/checks.py): the largest magnitude of a",
        " * Real parameter or input (SI units), the smallest step (s), the relative change",
        " * of the step taken as rounding, the fastest mode (rad/s) or decay (1/s). */",
        f"#define LARGEST {checks.LARGEST!r}",
        f"#define SMALLEST_STEP {checks.SMALLEST_STEP!r}",
        f"#define STEP_JITTER {checks.STEP_JITTER!r}",
        f"#define FASTEST_RATE {checks.FASTEST_RATE!r}",
        f'#define MODEL_GUID "{guid}"',
        f'#define MODEL_IDENTIFIER "{identifier}"',
        f'#define PLANT_BUILD "{build}"',
        f"#define N_VARS {len(variables)}",
        "enum { T_REAL, T_INTEGER, T_BOOLEAN, T_STRING };",
        "enum { C_PARAMETER, C_INPUT, C_OUTPUT };",
    ]
    macros: dict[str, int] = {}
    for vr, var in enumerate(variables):
        macros.setdefault(var.name.split("[")[0], vr)
    lines += [f"#define VR_{name} {vr}" for name, vr in macros.items()]

    def table(ctype: str, name: str, items: list[str]) -> None:
        lines.append(f"static const {ctype} {name}[N_VARS] = {{")
        lines.extend(f"    {item}," for item in items)
        lines.append("};")

    table("char *const", "VAR_NAME", [f'"{v.name}"' for v in variables])
    table("int", "VAR_TYPE", [_TYPES[v.type] for v in variables])
    table("int", "VAR_CAUSALITY", [_CAUSALITIES[v.causality] for v in variables])
    table(
        "double",
        "VAR_START",
        [
            "0.0" if isinstance(v.initial_value, str) else repr(float(v.initial_value))
            for v in variables
        ],
    )
    lines.append("#endif")
    return "\n".join(lines) + "\n"


def build_c_plant(n: int, destination: Path) -> Path:
    """Compile the plant for n load masses and package it as ``destination`` (.fmu)."""
    from xml.etree.ElementTree import fromstring

    identifier = PLANT.identifier(n)
    description = model_description_xml(identifier, n)
    guid = fromstring(description).get("guid")
    generated = {
        "chain_size.h": "/* Generated by arcosim: number of load masses. */\n"
        f"#define N_MASSES {n}\n",
        "plant_variables.h": variables_header(n, guid),
    }
    return compile_fmu(
        identifier,
        description,
        generated,
        [source_dir() / s for s in SOURCES],
        [source_dir() / h for h in HEADERS],
        destination,
    )


def compile_fmu(
    identifier: str,
    description: bytes,
    generated: dict[str, str],
    sources: list[Path],
    headers: list[Path],
    destination: Path,
) -> Path:
    """Compile C sources into an FMU (strict C99) and package it as ``destination``.

    Parameters
    ----------
    identifier : str
        The model identifier (the binary's name).
    description : bytes
        The modelDescription.xml.
    generated : dict of str to str
        Headers generated for this build, by file name.
    sources, headers : list of Path
        The C sources compiled and the headers they include (shipped under
        ``sources/`` with the envelope header and the generated ones); their folders
        are the include path.
    destination : Path
        The .fmu to write (atomically).

    Returns
    -------
    Path
        ``destination``.

    Raises
    ------
    BuildError
        When the compiler fails or warns.
    """
    folders = list(dict.fromkeys(p.parent for p in (*sources, *headers)))
    with tempfile.TemporaryDirectory(prefix="arcosim_cplant_") as tmp:
        folder = Path(tmp)
        for name, text in generated.items():
            (folder / name).write_text(text, encoding="utf-8")
        binary = folder / f"{identifier}.so"
        command = [
            compiler(),
            *CFLAGS,
            f"-I{folder}",
            *(f"-I{f}" for f in folders),
            f"-I{envelope_header().parent}",
            f"-I{fmi_headers()}",
            *(str(s) for s in sources),
            "-lm",
            "-o",
            str(binary),
        ]
        result = subprocess.run(command, capture_output=True, text=True)
        if result.returncode != 0 or result.stderr.strip():
            raise BuildError(
                f"compiling the {identifier} FMU failed:\n  {' '.join(command)}\n{result.stderr}"
            )
        destination.parent.mkdir(parents=True, exist_ok=True)
        partial = destination.with_name(f".{destination.name}.{folder.name}.part")
        with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("modelDescription.xml", description)
            z.write(binary, f"binaries/linux64/{identifier}.so")
            for path in (*sources, *headers):
                z.write(path, f"sources/{path.name}")
            z.write(envelope_header(), f"sources/{envelope_header().name}")
            for name, text in generated.items():
                z.writestr(f"sources/{name}", text)
        partial.replace(destination)
    return destination
