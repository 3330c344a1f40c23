"""mkdocs hook: stage the package as installed, for the API reference.

The package ``arcosim`` spans three folders of the repository (``cosim/`` is
``arcosim``, ``fmu_src/`` is ``arcosim.fmu``, ``plant_models/`` is ``arcosim.plant``);
griffe reads a package from one folder, so the hook copies the sources into
``.docs-src/arcosim`` in the installed layout before the pages are rendered.
"""

from __future__ import annotations

import shutil
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
STAGE = ROOT / ".docs-src"
LAYOUT = {"cosim": "arcosim", "fmu_src": "arcosim/fmu", "plant_models": "arcosim/plant"}


def on_startup(**_: object) -> None:
    shutil.rmtree(STAGE, ignore_errors=True)
    for folder, target in LAYOUT.items():
        for source in (ROOT / folder).rglob("*.py"):
            destination = STAGE / target / source.relative_to(ROOT / folder)
            destination.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, destination)
