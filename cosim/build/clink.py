"""Build the flexible-link plant FMU from C: ``plant_models/flexlink_c/`` (the beam's
physics and FMI shell) with the chain plant's shared helpers (``motorchain_c/``: the
matrix exponential, the friction events, the sensors), compiled as the chain plant is
(:func:`arcosim.build.cplant.compile_fmu`).

The number of Hermite elements is fixed at build time and carried in the model
identifier (``FlexLinkPlant_e8``), as the number of masses is for the chain. The
variables are declared here (:func:`link_variables`); the model description and the C
header of names and value references are generated from that one list.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from xml.etree.ElementTree import SubElement, fromstring, tostring

from arcosim.build.cache import plant_package_dir
from arcosim.build.cplant import HEADERS as CHAIN_HEADERS
from arcosim.build.cplant import compile_fmu, envelope_header, variables_table
from arcosim.build.cplant import source_dir as chain_dir
from arcosim.build.recipes import LINK, check_elements
from arcosim.fmu.flexchain import defaults
from arcosim.fmu.fmukit import Variable, array, inp, out, par
from arcosim.fmu.fmukit.slave import TRACE_FILE
from arcosim.version import __version__

SOURCES = ("beam.c", "fmu.c")
HEADERS = ("beam.h",)
#: The chain's headers the link includes (one home for the shared C helpers).
SHARED = tuple(h for h in CHAIN_HEADERS if h != "physics.h")

MODEL_TEXT = (
    "Motor-driven hub with an Euler-Bernoulli beam clamped to it (small deflection in the "
    "rotating frame, optional tip mass and inertia, stiffness-proportional damping, Hermite "
    "cubic elements), with the chain plant's current loop, Coulomb friction, encoder and "
    "noisy current sensor. Outputs follow the timing contract: after doStep(t, h) they are "
    "the sample at t + h, whose current is the one that acted over [t, t + h]."
)


def source_dir() -> Path:
    """Folder of the link's C sources (package data of :mod:`arcosim.plant`)."""
    return plant_package_dir() / "flexlink_c"


def _motor() -> list[Variable]:
    """The motor, sensor and current-loop parameters, named and described as the chain's."""
    return [
        par("J_m", defaults.J_M, "kg.m2", "Hub inertia: rotor, hub and clamp (everything rigid)"),
        par("k_t", defaults.K_T, "N.m/A", "Motor torque constant"),
        par("D_m", defaults.D_M, "N.m.s/rad", "Motor viscous friction coefficient"),
        par(
            "f_c",
            defaults.F_C,
            "N.m",
            "Motor Coulomb friction; the hub sticks while |drive torque| <= f_c",
        ),
    ]


def _link() -> list[Variable]:
    return [
        par("EI", defaults.LINK_EI, "N.m2", "Bending stiffness of the beam"),
        par("rhoA", defaults.LINK_RHOA, "kg/m", "Mass per length of the beam"),
        par("L", defaults.LINK_L, "m", "Length of the beam, clamp to tip"),
        par("m_tip", defaults.LINK_M_TIP, "kg", "Tip mass (a point at x = L)"),
        par("J_tip", defaults.LINK_J_TIP, "kg.m2", "Inertia of the tip mass about its centre"),
        par("r_hub", defaults.LINK_R_HUB, "m", "Radius of the clamp from the motor's axis"),
        par(
            "beta",
            defaults.LINK_BETA,
            "s",
            "Stiffness-proportional damping: C = beta K, mode j damped beta omega_j / 2",
        ),
    ]


def _sensors() -> list[Variable]:
    return [
        par(
            "encoder_cpr",
            defaults.ENCODER_CPR,
            "",
            "Encoder counts per revolution after quadrature (0 = ideal: exact angle and "
            "true velocity)",
        ),
        par("i_noise_std", defaults.I_NOISE_STD, "A", "Standard deviation of the current noise"),
        par("seed", 1, "", "Seed of the current-noise sequence (same seed, same noise)"),
        par(
            "current_bandwidth",
            0.0,
            "rad/s",
            "Bandwidth of the first-order current loop (0 = ideal: i = i_ref)",
        ),
    ]


def _outputs(elements: int) -> list[Variable]:
    node = "at node {} (x = {} L/" + f"{elements})"
    return [
        out("i_a", "A", "Measured current: mean over the step just finished, plus noise"),
        out("theta_m", "rad", "Measured motor angle (encoder, floored to whole counts)"),
        out(
            "omega_m",
            "rad/s",
            "Measured motor velocity: backward difference of theta_m over the step "
            "(true velocity when encoder_cpr = 0)",
        ),
        out("theta_m_true", "rad", "True motor (hub) angle (verification only)"),
        out("omega_m_true", "rad/s", "True motor (hub) velocity (verification only)"),
        out("w_tip", "m", "True tip deflection w(L) in the rotating frame"),
        out("alpha_tip", "rad", "True tip deflection angle w(L) / L"),
        out(
            "tau_reac",
            "N.m",
            "True torque the link exerts on the hub (eq. 7: root moment + r x root shear, "
            "from the root element's end forces); J_m domega_m/dt = k_t i - D_m omega_m - "
            "friction - tau_reac",
        ),
        out("tau_reac_mean", "N.m", "True tau_reac averaged over the step just finished"),
        out("i_true", "A", "True current averaged over the step just finished"),
        *array(out, "w", elements, "m", lambda i: "True deflection " + node.format(i, i)),
        *array(out, "w_slope", elements, "rad", lambda i: "True slope w' " + node.format(i, i)),
        *array(out, "w_rate", elements, "m/s", lambda i: "True dw/dt " + node.format(i, i)),
        *array(
            out, "w_slope_rate", elements, "rad/s", lambda i: "True dw'/dt " + node.format(i, i)
        ),
    ]


def link_variables(elements: int) -> list[Variable]:
    """Every variable of the link FMU with ``elements`` elements, in value-reference order.

    Parameters
    ----------
    elements : int
        Number of Hermite cubic elements.

    Returns
    -------
    list of Variable
        Input ``i_ref``, the parameters, the outputs, ``trace_file``.

    Examples
    --------
    >>> [v.name for v in link_variables(2)][-4:]
    ['w_rate[2]', 'w_slope_rate[1]', 'w_slope_rate[2]', 'trace_file']
    """
    return [
        inp("i_ref", 0.0, "A", "Current command; held over each communication step"),
        *_motor(),
        *_link(),
        *_sensors(),
        *_outputs(elements),
        TRACE_FILE,
    ]


def model_description_xml(elements: int) -> bytes:
    """The link FMU's modelDescription.xml."""
    from arcosim.fmu.fmukit.model_description import ModelInfo, model_description

    info = ModelInfo(LINK.identifier(elements), MODEL_TEXT, __version__)
    options = {
        "needsExecutionTool": "false",
        "canGetAndSetFMUstate": "true",
        "canSerializeFMUstate": "true",
    }
    root = model_description(info, link_variables(elements), options)
    files = SubElement(root.find("CoSimulation"), "SourceFiles")
    for name in SOURCES:
        SubElement(files, "File", {"name": name})
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + tostring(root, encoding="utf-8")


def _paths() -> tuple[list[Path], list[Path]]:
    sources = [source_dir() / s for s in SOURCES]
    headers = [source_dir() / h for h in HEADERS] + [chain_dir() / h for h in SHARED]
    return sources, headers


def sources_digest(elements: int) -> str:
    """First 10 hex digits of the SHA-256 of the link's C sources and its element count:
    the build field of its serialized states' identity."""
    digest = hashlib.sha256(f"elements={elements}".encode())
    for path in (*_paths()[0], *_paths()[1], envelope_header()):
        digest.update(path.read_bytes())
    return digest.hexdigest()[:10]


def build_link(elements: int, destination: Path) -> Path:
    """Compile the link with ``elements`` Hermite elements and package it as ``destination``.

    Parameters
    ----------
    elements : int
        Number of elements, :data:`~arcosim.build.recipes.MIN_ELEMENTS` to
        :data:`~arcosim.build.recipes.MAX_ELEMENTS`.
    destination : Path
        The .fmu to write.

    Returns
    -------
    Path
        ``destination``.

    Raises
    ------
    UserError
        When ``elements`` is out of range.
    BuildError
        When the compiler fails.

    Examples
    --------
    >>> build_link(2, Path("FlexLinkPlant-2.fmu")).name  # two elements
    'FlexLinkPlant-2.fmu'
    """
    check_elements(elements)
    description = model_description_xml(elements)
    guid = fromstring(description).get("guid")
    identifier = LINK.identifier(elements)
    generated = {
        "link_size.h": "/* Generated by arcosim: number of Hermite elements. */\n"
        f"#define N_ELEMENTS {elements}\n",
        "plant_variables.h": variables_table(
            link_variables(elements),
            identifier,
            sources_digest(elements),
            guid,
            f"cosim/build/clink.py (elements = {elements})",
        ),
    }
    sources, headers = _paths()
    return compile_fmu(identifier, description, generated, sources, headers, destination)
