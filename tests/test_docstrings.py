"""Every name of the public API is documented the numpydoc way: the ``__all__`` of
``arcosim`` and of its public subpackages (``tests/test_public_api.py``).

Functions and classes: a summary; every parameter of the signature under
*Parameters* (classes: *Parameters* or *Attributes*), each float or array with a unit
in parentheses, each array with its shape; *Returns* when something is returned;
*Examples* that run (no ``+SKIP``) and print what they say, in the namespace of the
module that defines the name. Errors: a summary. Data (tables, constants, the defaults
module): ``arcosim``'s in its catalogue, a subpackage's in its module.
"""

from __future__ import annotations

import doctest
import importlib
import inspect
import re
import sys

import numpy as np
import pytest
from numpydoc.docscrape import ClassDoc, FunctionDoc

import arcosim
from tests.test_public_api import PUBLIC_PACKAGES

#: Every public name as ``package.name``.
PUBLIC = [
    f"{package}.{name}"
    for package in PUBLIC_PACKAGES
    for name in importlib.import_module(package).__all__
    if name != "__version__"
]
#: Public names whose examples take over ~5 s (they build or run FMUs, or fit records).
SLOW_EXAMPLES = {
    "arcosim.build_all",
    "arcosim.check_log",
    "arcosim.identify_drive",
    "arcosim.identify_whole_chain",
    "arcosim.build.build_link",
    "arcosim.experiments.simulate_link",
    "arcosim.experiments.score_link",
    "arcosim.experiments.run_closed_loop",
    "arcosim.experiments.identify_chain",
    "arcosim.experiments.design_parameters",
    "arcosim.experiments.Runs",
    "arcosim.host.replay_tracking",
}
#: A unit in parentheses, e.g. "(A)", "(rad/s, shape (N,))", "(kg·m²)", or a word
#: that says there is none.
UNIT = re.compile(r"\([^)]*[A-Za-zΩµ°%²][^)]*\)|dimensionless|count|number of|index")


def public(qualified: str) -> object:
    """The object a public ``package.name`` names."""
    package, name = qualified.rsplit(".", 1)
    return getattr(importlib.import_module(package), name)


#: The public names that are functions and classes; the rest are data.
CALLABLE = [q for q in PUBLIC if inspect.isclass(public(q)) or inspect.isfunction(public(q))]


def documented(qualified: str):
    obj = public(qualified)
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


def test_the_data_are_few_and_named_in_capitals() -> None:
    """What is not a function or a class is a table or a constant (or the defaults)."""
    data = [q.rsplit(".", 1)[1] for q in PUBLIC if q not in CALLABLE]
    assert all(name.isupper() or name == "defaults" for name in data), data


@pytest.mark.parametrize("name", CALLABLE)
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
    [pytest.param(n, marks=pytest.mark.slow) if n in SLOW_EXAMPLES else n for n in CALLABLE],
)
def test_public_examples_run(name: str, build_fmus, tmp_path, monkeypatch) -> None:
    build_fmus(3)  # the examples that co-simulate find current FMUs in the session cache
    monkeypatch.chdir(tmp_path)
    obj, _ = documented(name)
    namespace = {**vars(sys.modules[obj.__module__]), "arcosim": arcosim, "np": np}
    test = doctest.DocTestParser().get_doctest(inspect.getdoc(obj) or "", namespace, name, None, 0)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    runner.run(test)
    assert runner.failures == 0, f"{name}: {runner.failures} example(s) failed (see output)"
