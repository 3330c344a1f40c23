"""Checks shared by the tests of every FMU."""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path


def step_from_resources(fmu: Path, folder: Path, input_name: str, output_name: str) -> float:
    """Unzip ``fmu`` into ``folder`` and, in ``python -I -S`` (no site-packages) with
    only its ``resources/`` on the path, instantiate the slave class, set
    ``input_name`` to 0.3, take 50 steps of 1 ms and return ``output_name``.

    Proves that the FMU bundles everything it needs and uses no numpy.
    """
    from xml.etree import ElementTree

    with zipfile.ZipFile(fmu) as z:
        z.extractall(folder)
        module = z.read("resources/slavemodule.txt").decode().strip()
        description = ElementTree.fromstring(z.read("modelDescription.xml"))
    identifier = description.find("CoSimulation").get("modelIdentifier")
    script = (
        "import sys; sys.path.insert(0, sys.argv[1])\n"
        f"from {module} import {identifier} as Slave\n"
        "s = Slave(instance_name='x')\n"
        "s.setup_experiment(0.0); s.enter_initialization_mode(); s.exit_initialization_mode()\n"
        f"s.set_real([s.vr['{input_name}']], [0.3])\n"
        "assert all(s.do_step(k * 1e-3, 1e-3) for k in range(50)), s.log_queue\n"
        "assert 'numpy' not in sys.modules\n"
        f"print(s.get_real([s.vr['{output_name}']])[0])\n"
    )
    result = subprocess.run(
        [sys.executable, "-I", "-S", "-c", script, str(folder / "resources")],
        capture_output=True,
        text=True,
        cwd=folder,
    )
    assert result.returncode == 0, result.stderr
    return float(result.stdout)
