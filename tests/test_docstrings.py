"""Every name of the public API (``arcosim.__all__``) is documented the numpydoc way.

Functions and classes: a summary; every parameter of the signature under
*Parameters* (classes: *Parameters* or *Attributes*), each float or array with a unit
in parentheses, each array with its shape; *Returns* when something is returned;
*Examples* that run (no ``+SKIP``) and print what they say. Errors: a summary.
"""

from __future__ import annotations

import doctest
import inspect
import re

import numpy as np
import pytest
from numpydoc.docscrape import ClassDoc, FunctionDoc

import arcosim

PUBLIC = [name for name in arcosim.__all__ if name != "__version__"]
#: Public names that are data, not callables: described in the catalogue only.
DATA = {"SCENARIOS", "COLUMN_UNITS"}
#: Public names whose examples take over ~5 s (they build FMUs or fit whole records).
SLOW_EXAMPLES = {"build_all", "check_log", "identify_drive", "identify_whole_chain"}
#: A unit in parentheses, e.g. "(A)", "(rad/s, shape (N,))", "(kg·m²)", or a word
#: that says there is none.
UNIT = re.compile(r"\([^)]*[A-Za-zΩµ°%²][^)]*\)|dimensionless|count|number of|index")


def documented(name: str):
    obj = getattr(arcosim, name)
    return obj, (ClassDoc(obj) if inspect.isclass(obj) else FunctionDoc(obj))


def is_error(obj: object) -> bool:
    return inspect.isclass(obj) and issubclass(obj, Exception)


def signature_parameters(obj: object) -> list[inspect.Parameter]:
    target = obj.__init__ if inspect.isclass(obj) else obj
    skip = (inspect.Parameter.VAR_POSITIONAL, inspect.Parameter.VAR_KEYWORD)
    params = inspect.signature(target).parameters.values()
    return [p for p in params if p.name != "self" and p.kind not in skip]


def test_the_catalogue_names_every_public_name() -> None:
    for name in arcosim.__all__:
        assert re.search(rf"^{re.escape(name)}\s+--", arcosim.__doc__, re.M) or name in (
            "__version__",
        ), name


@pytest.mark.parametrize("name", [n for n in PUBLIC if n not in DATA])
def test_public_name_has_a_numpydoc_docstring(name: str) -> None:
    obj, doc = documented(name)
    assert doc["Summary"], f"{name}: no summary line"
    if is_error(obj):
        return
    described = {
        p.name: p
        for section in ("Parameters", "Other Parameters", "Attributes")
        for p in doc[section]
    }
    for parameter in signature_parameters(obj):
        entry = next((p for k, p in described.items() if parameter.name in k.split(", ")), None)
        assert entry is not None, f"{name}: parameter {parameter.name!r} is not documented"
        text = f"{entry.type} {' '.join(entry.desc)}"
        if re.search(r"\bfloat\b|ndarray|array", entry.type):
            assert UNIT.search(text), f"{name}: {parameter.name} gives no unit: {text!r}"
        if re.search(r"ndarray|array_like", entry.type):
            assert "shape" in text, f"{name}: {parameter.name} gives no shape: {text!r}"
    if inspect.isfunction(obj):
        returns = inspect.signature(obj).return_annotation
        if returns not in (None, "None", inspect.Signature.empty):
            assert doc["Returns"] or doc["Yields"], f"{name}: no Returns section"
    examples = "\n".join(doc["Examples"])
    assert ">>>" in examples, f"{name}: no example"
    assert "+SKIP" not in examples, f"{name}: its example must run"


@pytest.mark.parametrize(
    "name",
    [
        pytest.param(n, marks=pytest.mark.slow) if n in SLOW_EXAMPLES else n
        for n in PUBLIC
        if n not in DATA
    ],
)
def test_public_examples_run(name: str, build_fmus, tmp_path, monkeypatch) -> None:
    build_fmus(3)  # the examples that co-simulate find current FMUs in the session cache
    monkeypatch.chdir(tmp_path)
    obj, _ = documented(name)
    test = doctest.DocTestParser().get_doctest(
        inspect.getdoc(obj) or "", {"arcosim": arcosim, "np": np}, name, None, 0
    )
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    runner.run(test)
    assert runner.failures == 0, f"{name}: {runner.failures} example(s) failed (see output)"
