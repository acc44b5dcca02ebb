"""The generic parts of ``methods/base.py``: summary(), the delegation defaults, table_schema."""

from __future__ import annotations

import numpy as np
import pytest
from flint import fmpq

from obsdesign.errors import InputError
from obsdesign.methods.base import Method, SummaryField, table_schema
from obsdesign.params import Parameters


class _Plain(Method):
    key = "plain"
    summary_fields = (
        SummaryField("λ", "lambda"),
        SummaryField("v_max"),
        SummaryField("K", fmt=".3g"),
        SummaryField("n", "count", "d"),
        SummaryField("absent"),
    )
    summary_format = ".4g"


def test_summary_formats_scalars_vectors_and_matrices() -> None:
    p = Parameters(
        {
            "lambda": fmpq(1, 3),
            "v_max": fmpq(2),
            "K": np.array([[fmpq(1, 3), 0], [2, fmpq(-1, 7)]], dtype=object),
            "count": 6,
        }
    )
    assert _Plain().summary(p) == "λ ≈ 0.3333, v_max = 2, K ≈ [0.333, 0; 2, -0.143], n = 6"
    vec = Parameters({"K": np.array([fmpq(1, 2), 3], dtype=object)})
    assert _Plain().summary(vec) == "K = [0.5, 3]"


def test_summary_field_param_defaults_to_label() -> None:
    assert SummaryField("v_max").param == "v_max"
    assert SummaryField("γ", "gamma").param == "gamma"
    assert SummaryField("v_max").fmt is None


def test_defaults_without_the_package_modules() -> None:
    """A method whose package has no sim module has no simulation (InputError); no SimOptions
    means no [simulate] keys of its own."""
    m = _Plain()
    with pytest.raises(InputError, match="has no simulation"):
        m.simulate(None, Parameters())  # type: ignore[arg-type]
    assert m.simulate_schema() == {}
    assert m.parse_simulate(None, None) is None  # type: ignore[arg-type]


def test_table_schema() -> None:
    s = table_schema("k", {"a": {"type": "number"}}, ("a",))
    assert s == {
        "type": "object",
        "required": ["key", "a"],
        "additionalProperties": False,
        "properties": {"key": {"const": "k"}, "a": {"type": "number"}},
    }


@pytest.mark.parametrize("text", ["", " ", "\t"])
def test_an_empty_path_option_is_refused(text: str) -> None:
    """``--option sampling_file=`` was Path('') = '.': '.: is a directory' (CLI review)."""
    from obsdesign.methods.base import SimOption

    opt = SimOption("sampling_file", "path", None, "a file")
    with pytest.raises(InputError, match=r"^--option sampling_file: expected a path, got "):
        opt.parse(text)
    with pytest.raises(InputError, match=r"^simulate: sampling_file: expected a path"):
        opt.check_value(text)
    assert opt.parse("h.txt").name == "h.txt"


def test_an_int_option_past_64_bits_is_refused_but_a_seed_is_not() -> None:
    """``max_centres = 10**400`` reached a float conversion (exit 4 blaming the spec) and
    ``runs = 10**400`` a bare OverflowError (API review, session 44): an int option above
    2^63 − 1 is refused by name; 2^63 − 1 itself passes, and a seed takes any size."""
    from obsdesign.methods.base import INT_MAX, SimOption

    opt = SimOption("max_centres", "int", None, "a cap", 1)
    assert opt.parse(str(INT_MAX)) == INT_MAX == opt.check_value(INT_MAX)
    for bad in (str(INT_MAX + 1), str(10**400)):
        with pytest.raises(InputError, match="max_centres: expected an integer of at most 2"):
            opt.parse(bad)
    with pytest.raises(InputError, match="simulate: max_centres: expected an integer of at"):
        opt.check_value(INT_MAX + 1)
    seed = SimOption("seed", "int", 0, "a seed")
    assert seed.check_value(10**400) == 10**400


def test_a_float_option_below_the_float_range_is_named_as_such() -> None:
    """``--option gamma=1e-400`` said "expected a positive number, got 0.0" (CLI review,
    session 44): the text is exactly nonzero, and the refusal says it reads as 0; 0 and -0
    themselves stay zero."""
    from obsdesign.methods.base import SimOption

    opt = SimOption("gamma", "float", None, "a gain")
    for text in ("1e-400", "-1e-400", " 2E-330 "):
        with pytest.raises(InputError, match="is below the float range"):
            opt.parse(text)
    assert opt.parse("0") == 0.0 and opt.parse("-0.0") == 0.0
    assert opt.parse("5e-324") == 5e-324
    # a typed value from the API too (re-check review, session 44)
    from decimal import Decimal
    from fractions import Fraction

    for v in (Decimal("1e-400"), Fraction(1, 10**400)):
        with pytest.raises(InputError, match="simulate: gamma: .* is below the float range"):
            opt.check_value(v)
    assert opt.check_value(Decimal("0")) == 0.0 and opt.check_value(0.5) == 0.5


def test_an_int_or_bool_option_takes_an_exact_value_only_when_it_is_whole() -> None:
    """``seed=Decimal('1E-400')`` ran with seed 0 and ``Fraction(10**20 + 1, 10**20)`` with
    seed 1: the double of the value was whole, the value not (re-check review 45). The value
    itself must be whole (1 or 0 for a true/false option); 3.0, Decimal('3'), Fraction(6, 2)
    and numpy integers and floats that are whole still pass."""
    from decimal import Decimal
    from fractions import Fraction

    import numpy as np

    from obsdesign.methods.base import SimOption

    seed = SimOption("seed", "int", 0, "a seed")
    flag = SimOption("plot", "bool", False, "a flag")
    for v in (Decimal("1E-400"), Fraction(10**20 + 1, 10**20), Decimal("2.0000000000000000001")):
        with pytest.raises(InputError, match="simulate: seed: expected an integer"):
            seed.check_value(v)
    for v in (Decimal("1.0000000000000000001"), Fraction(10**20 + 1, 10**20)):
        with pytest.raises(InputError, match="simulate: plot: expected"):
            flag.check_value(v)
    for v, want in ((3.0, 3), (Decimal("3"), 3), (Fraction(6, 2), 3), (np.float32(3), 3)):
        assert seed.check_value(v) == want
    # whole exact values past 2^53 are whole (their doubles are not the value: Decimal(2^60
    # + 1) was refused, re-check review 45), and a seed of True is no integer
    for v in (Decimal(2**60 + 1), Fraction(2**60 + 1), Decimal("1E+30"), Decimal("-0")):
        assert seed.check_value(v) == int(v)
    for v in (True, np.True_, Decimal("1E+999999999"), Decimal("Infinity")):
        with pytest.raises(InputError, match="simulate: seed: expected an integer"):
            seed.check_value(v)
    assert flag.check_value(Decimal("1")) is True and flag.check_value(np.bool_(False)) is False
