"""The method contract, checked for every registered method (in the style of cvxpy's shared
solver tests): a new method is covered the moment it is in the registry."""

from __future__ import annotations

import copy
import json
import tomllib
from pathlib import Path
from typing import Any

import jsonschema
import pytest
from flint import fmpq
from typer.testing import CliRunner

from obsdesign import api
from obsdesign.certify.exact import qparse, qstr, to_float
from obsdesign.cli import app
from obsdesign.errors import InputError
from obsdesign.methods import method_keys
from obsdesign.methods.base import Method
from obsdesign.report.model import Report

KEYS = method_keys()
runner = CliRunner()


@pytest.fixture(scope="module")
def reports() -> dict[str, Report]:
    """One design per method, from its own template (shared by the tests below)."""
    return {}


def _design(key: str, cache: dict[str, Report]) -> Report:
    if key not in cache:
        cache[key] = api.design(api.load_spec_text(api.template(key), f"{key}-template.toml"))
    return cache[key]


@pytest.mark.parametrize("key", KEYS)
def test_declarations(key: str) -> None:
    m = api.method(key)
    assert isinstance(m, Method) and m.key == key
    assert m.title and m.paper and "shared" not in m.paper
    assert m.Options is not None, "declare the typed Options"
    assert m.summary_fields, "declare summary_fields"
    assert m.required_params, "declare required_params"
    assert all(o.help for o in m.sim_options)


@pytest.mark.parametrize("key", KEYS)
def test_template_designs_verifies_and_summarizes(key: str, reports: dict[str, Report]) -> None:
    rep = _design(key, reports)
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    again, problems = Report.from_dict(json.loads(rep.to_json()))
    assert not problems
    assert api.verify(again).exit_code() == 0
    m = api.method(key)
    assert m.summary(rep.parameters).strip()
    for k in m.required_params:
        assert k in rep.parameters, k
    assert rep.solver.get("status") in {
        "optimal",
        "closed_form",
        "inaccurate",
        "infeasible",
        "failed",
    }


def _bump(v: Any) -> Any:
    """Every exact entry moved up by a little (1/1000 of itself, or 1/1000 when zero)."""
    if isinstance(v, list):
        return [_bump(x) for x in v]
    q = qparse(v)
    return qstr(q + (abs(q) / 1000 if q != 0 else fmpq(1, 1000)))


def _floats_of(v: Any) -> Any:
    if isinstance(v, list):
        return [_floats_of(x) for x in v]
    return float(to_float(qparse(v)))


@pytest.mark.parametrize("key", KEYS)
def test_tampered_parameters_fail_verify(key: str, reports: dict[str, Report]) -> None:
    """Each exact parameter a method requires, moved consistently (exact and float): verify
    must fail (exit 1) for at least one of them, and never pass all of them silently."""
    rep = _design(key, reports)
    base = json.loads(rep.to_json())
    exact = base["parameters"]["exact"]
    tried = [k for k in api.method(key).required_params if k in exact]
    assert tried, "no exact required parameter to tamper with"
    caught = []
    for k in tried:
        d = copy.deepcopy(base)
        d["parameters"]["exact"][k] = _bump(exact[k])
        d["parameters"][k] = _floats_of(d["parameters"]["exact"][k])
        r, problems = Report.from_dict(d)
        assert not problems
        if api.verify(r).exit_code() != 0:
            caught.append(k)
    assert caught, f"no tampered parameter of {tried} made verify fail"


@pytest.mark.parametrize("key", KEYS)
def test_unknown_option_is_bad_input(key: str) -> None:
    m = api.method(key)
    with pytest.raises(InputError, match="nosuchkey"):
        m.parse_sim_options({"nosuchkey": "1"})
    for o in m.sim_options:
        if o.kind in ("int", "float"):
            with pytest.raises(InputError, match=o.name):
                m.parse_sim_options({o.name: "abc"})


def test_unknown_option_exits_2_from_the_cli(tmp_path: Path) -> None:
    spec = tmp_path / "s.toml"
    spec.write_text(api.template("lyapunov"))
    res = runner.invoke(app, ["simulate", str(spec), "--option", "nosuchkey=1"])
    assert res.exit_code == 2


@pytest.mark.parametrize("key", KEYS)
def test_template_validates_against_schema(key: str) -> None:
    data = tomllib.loads(api.template(key))
    jsonschema.validate(data, api.schema())


def test_schema_covers_every_table() -> None:
    props = api.schema()["properties"]
    for t in ("system", "sets", "nonlinearity", "method", "simulate"):
        assert t in props
    assert len(props["method"]["oneOf"]) == len(KEYS)


@pytest.mark.parametrize("key", KEYS)
def test_template_has_a_docs_page_with_the_standard_headings(key: str) -> None:
    page = Path(__file__).resolve().parents[2] / "docs" / "methods" / f"{key}.md"
    assert page.exists(), page
    text = page.read_text(encoding="utf-8")
    heads = [ln[3:].strip() for ln in text.splitlines() if ln.startswith("## ")]
    assert heads == [
        "Spec keys",
        "What is certified",
        "Choices where the paper is ambiguous",
        "Reproduced numbers",
        "Limitations",
        "Benchmarks",
    ]
    assert "../shared" not in text


def _with_expression(text: str, key: str, n: int, p: int, m: int) -> str:
    """The template with ``[system] <key>`` added (a well-formed list of expressions)."""
    count = {"f": n, "psi": n, "h": p, "u": m}[key]
    var = "t" if key == "u" else "x1"
    line = f"{key} = [{', '.join([f'0.001*sin({var})'] * count)}]\n".replace("0.0", '"0.0')
    line = line.replace("), ", ')", ').replace(")]", ')"]')
    i = text.index("[system]") + len("[system]\n")
    return text[:i] + line + text[i:]


UNREAD = [
    (k, e) for k in KEYS for e in ("f", "psi", "h", "u") if e not in api.method(k).plant_expressions
]


@pytest.mark.parametrize(("key", "expr"), UNREAD)
def test_an_expression_the_method_does_not_read_is_refused(key: str, expr: str) -> None:
    """No certificate silently ignores part of the plant: an expression key of [system]
    outside the method's ``plant_expressions`` exits 2 naming system.<key>."""
    base = api.load_spec_text(api.template(key), "t.toml").system
    if base.f is not None or base.psi is not None:
        pytest.skip("the template already gives the plant by expressions")
    count = {"f": base.n, "psi": base.n, "h": base.p, "u": base.m}[expr]
    if count == 0:
        pytest.skip(f"no {expr} entries to give")
    text = _with_expression(api.template(key), expr, base.n, base.p, base.m)
    with pytest.raises(api.SpecError) as e:
        api.load_spec_text(text, "t.toml")
    assert f"system.{expr}" in str(e.value) and "is not read" in str(e.value)
