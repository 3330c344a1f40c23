"""Each rule lives in one place: a test imports it from its home, and a search of the
sources finds no second definition and no copy of its arithmetic.

Read from the source files of the package's three folders and of ``benchmarks/`` (their
syntax trees, f-strings included), not from what happens to be imported.
"""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np

from arcosim.fmu.flexchain import waveforms
from arcosim.identification.excitation.band import BAND_PER_G, SAMPLE_BAND, search_band
from arcosim.identification.excitation.design import LINE_T, design_excitation

ROOT = Path(__file__).resolve().parents[1]
#: Folders whose Python sources are searched.
SOURCES = ("cosim", "fmu_src", "plant_models", "benchmarks")
BAND = ROOT / "cosim" / "identification" / "excitation" / "band.py"


def trees() -> dict[Path, ast.Module]:
    return {
        path: ast.parse(path.read_text(encoding="utf-8"))
        for folder in SOURCES
        for path in sorted((ROOT / folder).rglob("*.py"))
    }


TREES = trees()


def definitions(name: str) -> list[str]:
    """The files that assign ``name`` at module level, once per assignment."""
    return [
        str(path.relative_to(ROOT))
        for path, tree in TREES.items()
        for node in tree.body
        if isinstance(node, (ast.Assign, ast.AnnAssign))
        and any(
            isinstance(t, ast.Name) and t.id == name
            for t in (node.targets if isinstance(node, ast.Assign) else [node.target])
        )
    ]


def is_number(node: ast.AST, *values: float) -> bool:
    return (
        isinstance(node, ast.Constant)
        and type(node.value) in (int, float)
        and (node.value in values)
    )


def names_g_dist(node: ast.AST) -> bool:
    return (isinstance(node, ast.Name) and node.id == "g_dist") or (
        isinstance(node, ast.Attribute) and node.attr == "g_dist"
    )


def band_arithmetic(node: ast.AST) -> bool:
    """``0.3 / h``-style (the sample rate's band) or ``3 * g_dist``-style (the DOB's)."""
    if not isinstance(node, ast.BinOp):
        return False
    if isinstance(node.op, ast.Div) and is_number(node.left, 0.3):
        return True
    if isinstance(node.op, ast.Mult):
        pair = (node.left, node.right)
        return any(is_number(a, 3) and names_g_dist(b) for a, b in (pair, pair[::-1]))
    return False


def test_the_line_threshold_has_one_home() -> None:
    assert LINE_T == 5.0
    assert definitions("LINE_T") == ["cosim/identification/excitation/design.py"]


def test_the_search_band_has_one_home() -> None:
    assert search_band(100.0, 1e-3) == min(BAND_PER_G * 100.0, SAMPLE_BAND / 1e-3) == 300.0
    assert search_band(50.0, 1e-3) == 150.0  # the DOB's limit
    assert search_band(200.0, 1e-3) == 300.0  # the sample rate's
    for name in ("BAND_PER_G", "SAMPLE_BAND"):
        assert definitions(name) == ["cosim/identification/excitation/band.py"]


def test_the_band_is_computed_only_in_its_home() -> None:
    copies = [
        f"{path.relative_to(ROOT)}:{node.lineno}: {ast.unparse(node)}"
        for path, tree in TREES.items()
        if path != BAND
        for node in ast.walk(tree)
        if band_arithmetic(node)
    ]
    assert not copies, "write search_band / sample_band / dob_band instead of: " + "; ".join(copies)
    homes = {
        node.name
        for node in ast.walk(TREES[BAND])
        if isinstance(node, ast.FunctionDef)
        for inner in ast.walk(node)
        if isinstance(inner, ast.Name) and inner.id in ("BAND_PER_G", "SAMPLE_BAND")
    }
    assert homes == {"dob_band", "sample_band"}
    users = [
        f"{path.relative_to(ROOT)}:{node.lineno}"
        for path, tree in TREES.items()
        if path != BAND
        for node in ast.walk(tree)
        if isinstance(node, ast.Name) and node.id in ("BAND_PER_G", "SAMPLE_BAND")
    ]
    assert not users, f"the band's constants used outside band.py: {users}"


def test_the_designed_current_is_the_excitation_sources_multisine() -> None:
    """The design's lines and phases are the FMU's, and its current the FMU's sum of
    sines (evaluated over the whole record at once: equal to rounding)."""
    design = design_excitation((3.0, 150.0), 3.0, duration=2.0, lines=12, seed=4)
    lines = waveforms.log_spaced(3.0, 150.0, 12)
    phases = waveforms.multisine_phases(12, 4)
    assert design.frequencies.tolist() == lines and design.phases.tolist() == phases
    played = [waveforms.multisine(t, 3.0, lines, phases) for t in design.time.tolist()]
    np.testing.assert_allclose(design.signal, played, rtol=0.0, atol=1e-14)
