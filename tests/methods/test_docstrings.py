"""Docstrings (in the style of python-control's docstrings_test.py): every public function of
``obsdesign.api`` documents itself and names its parameters; every public function of a
method's ``design`` and ``claims`` modules cites what of the paper it implements."""

from __future__ import annotations

import importlib
import inspect
import re

import pytest

from obsdesign import api
from obsdesign.methods import REGISTRY

CITES = re.compile(
    r"eq\.|eqs\.|\(\d+[a-z]?\)|Theorem|Lemma|Proposition|Definition|Section|Algorithm|"
    r"Corollary|Assumption|Example|LMI|Remark|Figure|Fig\.|slide",
    re.IGNORECASE,
)


def _public_functions(mod: object) -> list[tuple[str, object]]:
    return [
        (name, fn)
        for name, fn in inspect.getmembers(mod, inspect.isfunction)
        if not name.startswith("_") and fn.__module__ == mod.__name__  # type: ignore[attr-defined]
    ]


@pytest.mark.parametrize("name", [n for n, _ in _public_functions(api)])
def test_api_functions_document_their_parameters(name: str) -> None:
    fn = getattr(api, name)
    doc = inspect.getdoc(fn) or ""
    assert doc, f"api.{name} has no docstring"
    for p in inspect.signature(fn).parameters.values():
        if p.kind in (p.VAR_KEYWORD, p.VAR_POSITIONAL):
            continue
        assert re.search(rf"\b{p.name}\b", doc), f"api.{name}: parameter '{p.name}' undocumented"


def _method_modules() -> list[str]:
    out = []
    for target in REGISTRY.values():
        base = target.split(":")[0]
        for part in ("design", "claims"):
            out.append(f"{base}.{part}")
    return out


@pytest.mark.parametrize("modname", _method_modules())
def test_method_functions_cite_the_paper(modname: str) -> None:
    mod = importlib.import_module(modname)
    missing = [
        name for name, fn in _public_functions(mod) if not CITES.search(inspect.getdoc(fn) or "")
    ]
    assert not missing, f"{modname}: no citation in the docstring of {missing}"
