"""Every method's template (``obsdesign init KEY``) is a valid spec, and stays valid TOML when
ANY one of its commented ``# key = value`` lines is uncommented alone (issue 14 item 3)."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import jsonschema
import pytest

from obsdesign import api
from obsdesign.methods import method_keys
from obsdesign.spec.schema import expression_keys

#: a commented assignment: "# key = value", "#   key.sub = value  # note"
COMMENTED = re.compile(r"^(\s*)#\s?(\s*[A-Za-z_][\w.-]*\s*=\s*\S.*)$")


def commented_lines(text: str) -> list[int]:
    """Indices of the lines that look like a commented ``key = value``."""
    return [i for i, line in enumerate(text.splitlines()) if COMMENTED.match(line)]


def uncomment(text: str, i: int) -> str:
    lines = text.splitlines()
    m = COMMENTED.match(lines[i])
    assert m is not None
    lines[i] = m.group(1) + m.group(2)
    return "\n".join(lines) + "\n"


def test_pattern_finds_commented_assignments_only():
    text = '# a comment\n# f = ["x2"]      # note\n#   rate_cap = 10\n# [sets.X0]\n#: doc\nx = 1\n'
    assert commented_lines(text) == [1, 2]
    assert uncomment(text, 1).splitlines()[1] == 'f = ["x2"]      # note'


@pytest.mark.parametrize("key", method_keys())
def test_template_loads_as_a_spec(key: str):
    sp = api.load_spec_text(api.template(key), f"template:{key}")
    assert sp.method == key


@pytest.mark.parametrize("key", method_keys())
def test_any_single_comment_line_uncommented_is_valid_toml(key: str):
    text = api.template(key)
    tomllib.loads(text)
    idx = commented_lines(text)
    assert idx, f"{key}: the template shows no optional key"
    bad = []
    for i in idx:
        try:
            tomllib.loads(uncomment(text, i))
        except tomllib.TOMLDecodeError as e:
            bad.append(f"line {i + 1}: {text.splitlines()[i]!r}: {e}")
    assert not bad, f"{key}: " + "; ".join(bad)


SPECS = sorted((Path(__file__).resolve().parents[1] / "specs").glob("*.toml"))


@pytest.mark.parametrize("path", SPECS, ids=[p.name for p in SPECS])
def test_shipped_specs_validate_against_the_schema(path: Path):
    jsonschema.validate(tomllib.loads(path.read_text(encoding="utf-8")), api.schema())


def test_schema_marks_expression_keys_and_covers_nonlinearity():
    sch = api.schema()
    assert expression_keys(sch) == ["method.F", "system.f", "system.h", "system.psi", "system.u"]
    nl = sch["properties"]["nonlinearity"]
    assert set(nl["properties"]) == {"lipschitz_x", "o", "n", "falsify"}
    assert nl["additionalProperties"] is False
    bad = tomllib.loads(api.template("impulsive"))
    bad.setdefault("nonlinearity", {})["lipschitz_y"] = 1
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, sch)


@pytest.mark.parametrize(
    ("edit", "where"),
    [
        (("\n[system]\n", "\nbogus = 1\n[system]\n"), "top level"),
        (("\n[system]\n", "\n[system]\nBdd = [[1], [0]]\n"), "[system]"),
        (("\n[simulate]\n", "\n[simulate]\nhorizn = 30\n"), "[simulate]"),
        (('type = "box"', 'type = "box"\ncentre = [0, 0]'), "a set"),
    ],
)
def test_the_schema_refuses_the_unknown_keys_the_tool_refuses(edit, where) -> None:
    """Unknown keys are errors in the tool (exit 2), but the schema accepted them at the top
    level, in [system], [simulate] and in the sets (outsider trial, session 22). Both refuse
    them now."""
    from obsdesign.errors import SpecError

    text = (SPECS[0].parent / "constrained-redesign-sec5.toml").read_text(encoding="utf-8")
    assert edit[0] in text, where
    bad = text.replace(edit[0], edit[1], 1)
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(tomllib.loads(bad), api.schema())
    with pytest.raises(SpecError):
        api.load_spec_text(bad, "typo.toml")


@pytest.mark.parametrize(
    ("spec", "foreign"),
    [
        ("constrained-redesign-sec5-lyapunov.toml", "theta_m = 3"),
        ("schaum-impulsive-example.toml", "max_centres = 10"),
        ("hernandez-garcia-example.toml", "amplitudes = [1, 10]"),
    ],
)
def test_the_schema_ties_simulate_keys_to_the_method(spec: str, foreign: str) -> None:
    """[simulate] was one union of every method's keys: a lyapunov spec with theta_m (a
    constrained key) validated, then design refused it, exit 2 (outsider trial, session 29).
    The schema refuses another method's key as the tool does, and keeps the spec's own."""
    from obsdesign.errors import SpecError

    text = (SPECS[0].parent / spec).read_text(encoding="utf-8")
    assert "\n[simulate]\n" in text
    jsonschema.validate(tomllib.loads(text), api.schema())
    bad = text.replace("\n[simulate]\n", f"\n[simulate]\n{foreign}\n", 1)
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(tomllib.loads(bad), api.schema())
    with pytest.raises(SpecError):
        api.load_spec_text(bad, "foreign.toml")


def test_a_simulate_key_of_several_methods_is_checked_by_the_spec_methods_rule() -> None:
    """Every method's [simulate] rules went into one dict, the last method's winning:
    search-space ``substeps = 0`` (its documented default) was refused by the schema and
    impulsive ``runs = 200000`` accepted, the tool doing the opposite (docs review 45). Each
    method's branch carries its own rules; the falsification's ``samples`` has the tool's
    maximum too."""
    from obsdesign.errors import SpecError
    from obsdesign.methods.impulsive.options import MAX_SAMPLES
    from obsdesign.spec.schema import _capped_integers

    schema = api.schema()
    branches = {
        b["if"]["properties"]["method"]["properties"]["key"]["const"]: b for b in schema["allOf"]
    }
    for m in api.methods():
        own = branches[m.key]["then"]["properties"]["simulate"]["properties"]
        # (with the integer cap the schema adds: session 45)
        want = {k: _capped_integers(v, k) for k, v in m.simulate_schema().items()}
        assert own == want, m.key
    root = SPECS[0].parent
    ss = (root / "hernandez-garcia-example.toml").read_text(encoding="utf-8")
    ok = ss.replace("\n[simulate]\n", "\n[simulate]\nsubsteps = 0\n", 1)
    jsonschema.validate(tomllib.loads(ok), schema)
    api.load_spec_text(ok, "ss.toml")
    imp = (root / "schaum-impulsive-example.toml").read_text(encoding="utf-8")
    assert "\nruns = 20\n" in imp
    for text in (
        imp.replace("\nruns = 20\n", "\nruns = 200000\n", 1),
        imp.replace("samples = 20000\n", f"samples = {MAX_SAMPLES + 1}\n", 1),
    ):
        with pytest.raises(jsonschema.ValidationError):
            jsonschema.validate(tomllib.loads(text), schema)
        with pytest.raises(SpecError):
            api.load_spec_text(text, "imp.toml")
    text = imp.replace("samples = 20000\n", f"samples = {MAX_SAMPLES}\n", 1)
    jsonschema.validate(tomllib.loads(text), schema)
    api.load_spec_text(text, "imp.toml")


def test_the_schema_refuses_the_values_every_loader_refuses() -> None:
    """The schema accepted horizon = 0 for every method, integers past 2^63 − 1 (runs,
    max_centres), stubborn amplitudes = [] and constrained saturation_r ≤ 0, all refused by
    the tool (re-check review 45); a seed of any size is valid in both."""
    from obsdesign.errors import SpecError

    schema = api.schema()
    root = SPECS[0].parent
    cases = {
        "hernandez-garcia-example.toml": (
            "\n[simulate]\n",
            ["horizon = 0", "max_centres = 9223372036854775808"],
        ),
        "astolfi-stubborn-example1.toml": (
            "\n[simulate]\n",
            ["amplitudes = []", "runs = 9223372036854775808"],
        ),
        "constrained-redesign-sec5.toml": (
            "\n[simulate]\n",
            # theta_m past 2^63 − 1: the schema refused it and the loader took it (re-check 46)
            ["saturation_r = 0", "saturation_r = [1, -1]", "theta_m = [10, 9223372036854775808]"],
        ),
    }
    for name, (anchor, bad_lines) in cases.items():
        text = (root / name).read_text(encoding="utf-8")
        assert anchor in text
        for line in bad_lines:
            key = line.split(" =")[0]
            base = "\n".join(x for x in text.split("\n") if not x.startswith(f"{key} ="))
            bad = base.replace(anchor, f"{anchor}{line}\n", 1)
            with pytest.raises(jsonschema.ValidationError):
                jsonschema.validate(tomllib.loads(bad), schema)
            with pytest.raises(SpecError):
                api.load_spec_text(bad, name)
    text = (root / "hernandez-garcia-example.toml").read_text(encoding="utf-8")
    big_seed = text.replace("\n[simulate]\n", f"\n[simulate]\nseed = {2**70}\n", 1)
    jsonschema.validate(tomllib.loads(big_seed), schema)
    api.load_spec_text(big_seed, "seed.toml")


def test_the_schema_takes_a_saturation_level_per_state() -> None:
    """The cap of session 45 limited constrained saturation_r to 2 entries: a 3-state spec
    with one level per state designs but was invalid under the schema (re-check review 45).
    Any number of positive levels is valid; the count (1 or n) is the tool's cross-key check."""
    doc = tomllib.loads(api.template("constrained"))
    doc.setdefault("simulate", {})["saturation_r"] = [2.0, 2.0, 2.0]
    errs = [
        e
        for e in jsonschema.Draft202012Validator(api.schema()).iter_errors(doc)
        if "saturation_r" in "/".join(map(str, e.absolute_path))
    ]
    assert not errs, [e.message for e in errs]


def test_the_schema_and_the_reader_agree_on_one_number_bounds_and_empty_windows() -> None:
    """A vector key the reader takes as one number (a 1-D box bound, the outlier amplitudes)
    was invalid under the schema, and windows = [] was valid though the reader refuses it
    (re-check review 46)."""
    from obsdesign.errors import SpecError

    schema = api.schema()
    root = SPECS[0].parent
    ss = (root / "hernandez-garcia-example.toml").read_text(encoding="utf-8")
    st = (root / "astolfi-stubborn-example1.toml").read_text(encoding="utf-8")
    co = (root / "constrained-redesign-sec5.toml").read_text(encoding="utf-8")
    good = [
        ss.replace("lower = [0]\nupper = [1]", "lower = 0\nupper = 1"),
        st.replace("amplitudes = [0.1, 1, 10, 100, 1000]", "amplitudes = 5"),
        co.replace("[method.D]\nlower = [-3]\nupper = [3]", "[method.D]\nlower = -3\nupper = 3"),
    ]
    for text in good:
        assert text not in (ss, st, co)
        jsonschema.validate(tomllib.loads(text), schema)
        api.load_spec_text(text, "one.toml")
    one_state = (
        '[system]\ntime = "discrete"\nA = [[0.5]]\nC = [[1]]\n[method]\nkey = "lyapunov"\n'
        'L = [0.2]\n[sets.E0]\ntype = "ellipsoid"\nE = [[1]]\ncenter = 0\n[simulate]\n'
        'horizon = 5\nx0 = 1\nxhat0 = 0\n[simulate.noise]\nkind = "constant"\nvalue = 3\n'
    )  # x0, xhat0, a signal's value, an ellipsoid's center as one number (docs review 46)
    jsonschema.validate(tomllib.loads(one_state), schema)
    api.load_spec_text(one_state, "one.toml")
    ly = (root / "constrained-redesign-sec5-lyapunov.toml").read_text(encoding="utf-8")
    bad = ly.replace("windows = [{ start = 151, stop = 153, value = [3] }]", "windows = []")
    assert bad != ly
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(tomllib.loads(bad), schema)
    with pytest.raises(SpecError):
        api.load_spec_text(bad, "w.toml")
