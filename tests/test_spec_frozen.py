"""Read-only spec data (obsdesign/spec/frozen.py): the arrays of a bound spec's sets and method
options, also in copies."""

from __future__ import annotations

import copy
import pickle
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest
from flint import fmpq

from obsdesign import api
from obsdesign.spec.frozen import freeze_arrays

SPECS = Path(__file__).resolve().parents[1] / "specs"


def test_freeze_walks_dataclasses_containers_and_views() -> None:
    @dataclass
    class Inner:
        a: np.ndarray
        rest: list = field(default_factory=list)

    base = np.arange(6.0)
    obj = {"x": (Inner(base[:3], [np.zeros(2), {"y": np.ones(1)}]),)}
    freeze_arrays(obj)
    inner = obj["x"][0]
    for arr in (inner.a, base, inner.rest[0], inner.rest[1]["y"]):
        with pytest.raises(ValueError, match="read-only"):
            arr[0] = 7.0
    loop: list = []
    loop.append(loop)
    freeze_arrays(loop)  # a cycle ends


def test_set_and_option_arrays_of_a_bound_spec_are_read_only() -> None:
    """A polytope's G_q, the search-space box E and the constrained map's G_q were writable:
    editing G_q left the set's float view G at the old value, and an E edited in place
    designed (exit 0) a report whose embedded text said another E (API review, session 43)."""
    om = api.load_spec(SPECS / "dorea-pimenta-7-1.toml").sets["omega"]
    with pytest.raises(ValueError, match="read-only"):
        om.G_q[0, 0] = fmpq(5)
    ss = api.load_spec(SPECS / "hernandez-garcia-example.toml")
    with pytest.raises(ValueError, match="read-only"):
        ss.options.E.upper_q[0] = fmpq(1, 10)
    cs = api.load_spec(SPECS / "constrained-redesign-sec5.toml")
    with pytest.raises(ValueError, match="read-only"):
        cs.options.cmap.G_q[0, 0] = fmpq(5)
    # copies are made writable by numpy; the next API call freezes them again
    other = copy.deepcopy(ss)
    api.bind(other)
    with pytest.raises(ValueError, match="read-only"):
        other.options.E.upper_q[0] = fmpq(1, 10)
    other = pickle.loads(pickle.dumps(cs))
    api.bind(other)
    with pytest.raises(ValueError, match="read-only"):
        other.options.cmap.G_q[0, 0] = fmpq(5)
    # the [simulate] scenario too (its noise bound was writable; re-check review, session 43)
    sim = api.load_spec(SPECS / "impulsive-sector-3state.toml").simulate
    assert isinstance(sim.noise.bound, np.ndarray)
    with pytest.raises(ValueError, match="read-only"):
        sim.noise.bound[0] = 5.0


def _mutations() -> list:
    """(name, edit of a loaded spec in place, the part the refusal names)."""
    import dataclasses

    from obsdesign.sets import Box
    from obsdesign.spec.reader import Value

    def system(sp):
        sp.system = dataclasses.replace(sp.system, A=Value.of([[0, 1], [0.99, 0]]))

    def text(sp):
        sp.text = sp.text.replace("[method]", "# edited\n[method]")

    def option_field(sp):
        sp.options.rate = fmpq(99, 100)

    def options(sp):
        sp.options = copy.copy(sp.options)

    def method(sp):
        sp.method = "stubborn"

    def shared_sets(sp):  # a copy shares the sets dict: the original changes
        other = copy.copy(sp)
        other.sets["Y"] = Box(np.array([-2.0, -2.0]), np.array([2.0, 2.0]))

    return [
        ("system", system, r"\[system\]"),
        ("text", text, "text"),
        ("option field", option_field, r"\[method\] option 'rate'"),
        ("options", options, r"\[method\] options"),
        ("method", method, "spec.method was assigned 'stubborn', but its .method. table is for"),
        ("shared sets", shared_sets, r"\[sets\]"),
    ]


@pytest.mark.parametrize(("name", "edit", "named"), _mutations(), ids=[m[0] for m in _mutations()])
def test_design_refuses_a_spec_changed_after_loading(name, edit, named) -> None:
    """A report embeds the spec's text: a system replaced, the text or an option assigned, or a
    set put into the sets dict a copy shares with the original designed exit 0 with claims
    false for the embedded text (API review, session 44). Refused, exit 2, naming the part."""
    from obsdesign.errors import InputError

    sp = api.load_spec(SPECS / "constrained-redesign-sec5-lyapunov.toml")
    sp.options.rate = sp.options.rate  # the same object again: nothing changed
    assert api.design(sp).exit_code() == 0
    edit(sp)
    with pytest.raises(InputError, match=named) as e:
        api.design(sp)
    assert e.value.exit_code == 2 and "load it again" in str(e.value)


def test_unchanged_copies_design() -> None:
    """Copies (shallow, deep, pickled) of an unchanged spec are the same value: designed."""
    sp = api.load_spec(SPECS / "constrained-redesign-sec5-lyapunov.toml")
    for other in (copy.copy(sp), copy.deepcopy(sp), pickle.loads(pickle.dumps(sp))):
        assert api.design(other).exit_code() == 0


def _with_k() -> str:
    text = (SPECS / "hernandez-garcia-example.toml").read_text(encoding="utf-8")
    old = 'f = ["u1*x2", "-u1*x1"]'
    assert old in text
    return text.replace(old, 'f = ["k*u1*x2", "-u1*x1"]').replace(
        "[method]", "[system.parameters]\nk = 10\n\n[method]", 1
    )


def test_expression_and_system_parameters_are_read_only() -> None:
    """``spec.system.f[0].parameters["k"] = 1`` designed a report certified for k = 1 (L_f = 1)
    whose embedded text says k = 10 (re-check review, session 44): refused, in copies too."""
    sp = api.load_spec_text(_with_k(), "k.toml")
    for other in (sp, copy.deepcopy(sp), pickle.loads(pickle.dumps(sp))):
        for d in (other.system.parameters, other.system.f[0].parameters):
            with pytest.raises(TypeError, match="read-only"):
                d["k"] = 1
            with pytest.raises(TypeError, match="read-only"):
                d.update(k=1)
        assert other.system.f[0](x1=0.0, x2=1.0, u1=1.0) == 10.0


def test_specs_with_expressions_pickle_and_design() -> None:
    """Every spec with an expression failed to pickle (its compiled callable is a closure;
    API review, session 44); an unpickled spec (ints and floats in its options are new
    objects) designs as the original."""
    sp = api.load_spec_text(_with_k(), "k.toml")
    back = pickle.loads(pickle.dumps(sp))
    assert back.system.f[0].source == "k*u1*x2"
    a, b = api.design(sp), api.design(back)
    assert b.exit_code() == a.exit_code() == 0
    assert b.parameters["L_f"] == a.parameters["L_f"]


def test_certify_refuses_a_spec_whose_method_key_was_assigned() -> None:
    """``spec.method = "constrained"`` on a lyapunov spec: ``certify`` checked the lyapunov
    report against the constrained contract (its options still lyapunov's), and ``design``
    was a bare AttributeError (API review, session 44). Refused by every API call."""
    from obsdesign.errors import InputError

    sp = api.load_spec(SPECS / "constrained-redesign-sec5-lyapunov.toml")
    rep = api.design(sp)
    sp.method = "constrained"
    for call in (lambda: api.certify(sp, rep.parameters), lambda: api.simulate(sp, rep)):
        with pytest.raises(InputError, match="spec.method was assigned 'constrained'"):
            call()


def test_an_expression_read_under_raised_limits_unpickles_under_the_defaults() -> None:
    """Expressions pickle as their source and are parsed again when loaded: under a Dask
    worker's default limits, a spec read with --limit max_expr_chars=20000 failed to
    deserialize and ``simulate --workers 2`` ended exit 3 after 60 s (re-check review,
    session 44). The source was checked once; loading it takes any size."""
    from obsdesign.limits import restore, saved, set_limits

    text = _with_k().replace('"k*u1*x2"', '"k*u1*x2 + ' + "0" * 12_000 + '*x1"')
    state = saved()
    try:
        set_limits(max_expr_chars=20_000)
        data = pickle.dumps(api.load_spec_text(text, "long.toml"))
    finally:
        restore(state)
    back = pickle.loads(data)  # the default limit, 10,000 characters
    assert len(back.system.f[0].source) > 12_000
    assert back.system.f[0](x1=1.0, x2=1.0, u1=1.0) == 10.0


def test_design_refuses_a_nested_option_or_an_expression_tree_edited_in_place() -> None:
    """``sp.options.problem.w_bar = 0`` (a field of a nested options object) certified a ball
    radius of 0 for a spec whose noise bound is 0.1, and an expression's tree edited in place
    (u1*x2 made 0.2*x2) certified f_sup = 2.55 for an f whose bound is 3.54 (re-check review,
    session 44): both refused, exit 2, naming the part."""
    import ast

    from obsdesign.errors import InputError

    sp = api.load_spec(SPECS / "schaum-impulsive-example.toml")
    sp.options.problem.w_bar = fmpq(0)
    with pytest.raises(InputError, match=r"\[method\] option 'problem.w_bar' of the spec"):
        api.design(sp)
    sp = api.load_spec(SPECS / "hernandez-garcia-example.toml")
    assert api.design(sp).exit_code() == 0
    f0 = sp.system.f[0]
    f0.tree.body.left = ast.copy_location(ast.Constant(0.2), f0.tree.body.left)
    with pytest.raises(InputError, match=r"\[system.f\]\[0\] expression of the spec object"):
        api.design(sp)


def test_design_refuses_a_system_list_edited_in_place() -> None:
    """System is frozen, its lists are not: ``f[0] = <another expression>`` or a state
    renamed in place designed claims for another plant than the text's (API reviews,
    sessions 43-44): refused, exit 2."""
    from obsdesign.errors import InputError

    sp = api.load_spec(SPECS / "hernandez-garcia-example.toml")
    other = api.load_spec_text(_with_k(), "k.toml").system.f[0]
    sp.system.f[0] = other
    with pytest.raises(InputError, match="expressions or state names of the spec object"):
        api.design(sp)
    sp = api.load_spec(SPECS / "constrained-redesign-sec5-lyapunov.toml")
    sp.system.states[0] = "renamed"
    with pytest.raises(InputError, match="expressions or state names"):
        api.design(sp)
