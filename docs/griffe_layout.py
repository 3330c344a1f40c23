"""griffe extension: read the package ``arcosim`` from its folders, under its installed names.

``arcosim`` spans three folders of the repository, mapped by ``pyproject.toml``'s
``[tool.setuptools.package-dir]`` (``cosim/`` is ``arcosim``, ``fmu_src/`` is
``arcosim.fmu``, ``plant_models/`` is ``arcosim.plant``). griffe finds a package by the
name of its folder: it finds no folder ``arcosim``, falls back to importing ``arcosim``
(the editable install maps it) and inspecting it, and sees neither ``arcosim.fmu`` nor
``arcosim.plant``, which are not under ``cosim/``. When griffe has loaded ``arcosim``,
this extension reads the three folders in place, statically as griffe reads any
package, and puts that package in its place. Nothing is copied.

Used by mkdocstrings (``mkdocs.yml``: ``extensions: [docs/griffe_layout.py:InstalledLayout]``).
"""

from __future__ import annotations

import re
import sys
from pathlib import Path
from typing import Any

import griffe

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]


def package_folders() -> dict[str, Path]:
    """Each package ``pyproject.toml`` maps to a folder of its own → that folder."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    mapping = config["tool"]["setuptools"]["package-dir"]
    return {package: ROOT / folder for package, folder in mapping.items()}


def read_module(
    name: str, path: Path, parent: griffe.Module | None, loader: griffe.GriffeLoader
) -> griffe.Module:
    """One module read from its source, as griffe's loader reads it."""
    code = path.read_text(encoding="utf-8-sig")
    loader.lines_collection[path] = code.splitlines(keepends=False)
    return griffe.visit(
        name,
        filepath=path,
        code=code,
        extensions=loader.extensions,
        parent=parent,
        docstring_parser=loader.docstring_parser,
        docstring_options=loader.docstring_options,
        lines_collection=loader.lines_collection,
        modules_collection=loader.modules_collection,
    )


def read_package(
    package: str,
    folder: Path,
    folders: dict[str, Path],
    loader: griffe.GriffeLoader,
    parent: griffe.Module | None = None,
) -> griffe.Module:
    """``package`` from ``folder``: its modules, its subfolders, and its mapped subpackages."""
    module = read_module(package.rpartition(".")[2], folder / "__init__.py", parent, loader)
    children = {
        path.stem: path for path in sorted(folder.glob("*.py")) if path.name != "__init__.py"
    }
    children |= {p.name: p for p in sorted(folder.iterdir()) if (p / "__init__.py").is_file()}
    children |= {
        name.rpartition(".")[2]: path
        for name, path in folders.items()
        if name.rpartition(".")[0] == package
    }
    for name, path in children.items():
        if path.suffix == ".py":
            child = read_module(name, path, module, loader)
        else:
            child = read_package(f"{package}.{name}", path, folders, loader, module)
        module.set_member(name, child)
    return module


class InstalledLayout(griffe.Extension):
    """Replace what griffe loaded of a package mapped to several folders by those folders."""

    def __init__(self) -> None:
        super().__init__()
        self.replacing = False

    def on_package(self, *, pkg: griffe.Module, loader: griffe.GriffeLoader, **_: Any) -> None:
        folders = package_folders()
        if self.replacing or pkg.name not in folders:
            return
        package = read_package(pkg.name, folders[pkg.name], folders, loader)
        loader.modules_collection.set_member(package.path, package)
        loader.expand_exports(package)
        loader.expand_wildcards(package, external=False)
        convert_roles(package, loader.modules_collection)
        self.replacing = True
        try:  # the other extensions (griffe's dataclasses) see the package read here
            loader.extensions.call("on_package", pkg=package, loader=loader)
        finally:
            self.replacing = False


#: A Sphinx role in a docstring: ``:func:`name```, ``:class:`~arcosim.x.Name```,
#: ``:ref:`text <target>```.
ROLE = re.compile(
    r":(?:py:)?(?P<role>func|mod|class|data|meth|attr|ref|obj|exc|const):`(?P<target>[^`]+)`"
)


#: A line of a package's catalogue: ``name   -- what it holds`` (continued below,
#: indented to the text).
CATALOGUE = re.compile(r"^(?P<name>[A-Za-z_][\w.]*(?:, [A-Za-z_][\w.]*)*) +-- (?P<text>.*)$")


def convert_roles(obj: griffe.Object, collection: griffe.ModulesCollection) -> None:
    """Rewrite the docstrings of ``obj`` and its members for Markdown, in the loaded copy.

    A Sphinx role whose target griffe finds becomes an optional cross-reference (a
    link when the target has a page, its name in code otherwise); any other becomes
    code. A package's catalogue (``name -- text`` lines) becomes a list, where
    Markdown would run its lines together into one paragraph. The sources keep both
    as they are: ``help()`` and the terminal read them there.
    """
    docstring = obj.docstring
    if docstring is not None:
        text = catalogue_lists(
            ROLE.sub(lambda m: markdown_role(m, obj, collection), docstring.value)
        )
        if text != docstring.value:
            docstring.value = text
            docstring.__dict__.pop("parsed", None)  # parsed again from the new text
    for member in obj.members.values():
        if not member.is_alias:
            convert_roles(member, collection)


def catalogue_lists(text: str) -> str:
    """Catalogue lines (``name -- text`` and their indented continuations) as a list."""
    out: list[str] = []
    item = False
    for line in text.split("\n"):
        match = CATALOGUE.match(line)
        if match:
            out.append(f"- `{match['name']}` — {match['text']}")
            item = True
        elif item and line.startswith("    ") and line.strip():
            out[-1] += " " + line.strip()
        else:
            out.append(line)
            item = False
    return "\n".join(out)


def markdown_role(match: re.Match, obj: griffe.Object, collection: griffe.ModulesCollection) -> str:
    """One role as Markdown: ``<autoref optional …><code>name</code></autoref>`` or code."""
    target = match["target"].strip()
    if match["role"] == "ref":
        text, _, _ = target.partition("<")
        return text.strip()
    short = target.startswith("~")
    target = target.lstrip("~!.")
    shown = target.rpartition(".")[2] if short else target
    path = resolved(target, obj, collection)
    code = f"<code>{shown}</code>"
    if path is None:
        return f"`{shown}`"
    return f'<autoref identifier="{path}" optional>{code}</autoref>'


def resolved(target: str, obj: griffe.Object, collection: griffe.ModulesCollection) -> str | None:
    """The full path of ``target`` as seen from ``obj``, if griffe has that object."""
    head, _, rest = target.partition(".")
    candidates = [target]
    scope = obj if obj.is_module or obj.is_class else obj.parent
    try:
        first = scope.resolve(head) if scope is not None else head
        candidates.insert(0, f"{first}.{rest}" if rest else first)
    except (griffe.NameResolutionError, AttributeError):
        pass
    for path in candidates:
        try:
            collection[path]
        except (KeyError, ValueError, AttributeError, griffe.AliasResolutionError):
            continue
        return path
    return None
