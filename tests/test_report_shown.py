"""Parameter values in tables and summaries (:mod:`obsdesign.report.shown`): "≈" exactly when
the decimal shown is not the value held (rendering trial, session 27: a certified rate
α = 43333331/20000000 showed as "2.16667 exact", a rate its bracket proves infeasible)."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from flint import fmpq
from hypothesis import given
from hypothesis import strategies as st

from obsdesign.certify.exact import Q
from obsdesign.methods import get_method
from obsdesign.params import Parameters
from obsdesign.report import shown as shown_mod
from obsdesign.report.shown import cell, item, shown


def _exact(*vals: fmpq) -> tuple[np.ndarray, np.ndarray]:
    raw = np.array(vals, dtype=object)
    return raw, np.array([float(v) for v in vals])


def test_a_rounded_exact_value_is_marked() -> None:
    alpha = fmpq(43333331, 20000000)  # 2.16666655; 2.16667 is above the proven bracket end
    assert cell(alpha, float(alpha)) == "≈ 2.16667"
    assert item("alpha", alpha, float(alpha), ".6g") == "alpha ≈ 2.16667"
    assert cell(fmpq(3, 2), 1.5) == "1.5"  # exact: no mark
    assert item("L", fmpq(-187, 100), -1.87, ".6g") == "L = -1.87"
    # one ulp of the sixth digit away either way is rounded, in both directions
    for q in (fmpq(1000001, 10**6), fmpq(999999, 10**6) + fmpq(1, 10**12)):
        assert cell(q, float(q)).startswith("≈ ")


def test_a_matrix_is_marked_when_any_entry_is_rounded() -> None:
    raw, fl = _exact(fmpq(1), fmpq(2), fmpq(1, 3), fmpq(4))
    assert cell(raw.reshape(2, 2), fl.reshape(2, 2)) == "≈ [1, 2; 0.333333, 4]"
    raw, fl = _exact(fmpq(1), fmpq(-5, 2))
    assert cell(raw, fl) == "[1, -2.5]"
    big = fmpq(10) ** 400  # beyond the float range: shown as inf, which it is not
    assert cell(big, float("inf")) == "≈ inf"


def test_a_float_parameter_is_exact_when_its_text_reads_back() -> None:
    assert cell(0.1, 0.1) == "0.1"  # the float 0.1 is what the report holds
    assert cell(0.1 + 2**-40, 0.1 + 2**-40) == "≈ 0.1"
    assert cell(float("inf"), float("inf")) == "inf"
    assert cell(float("nan"), float("nan")) == "nan"


@given(st.fractions(min_value=-1e6, max_value=1e6, max_denominator=10**9))
def test_the_mark_is_there_iff_the_text_is_not_the_value(x) -> None:
    q = Q(x)
    text, same = shown(q, float(q), ".6g")
    assert same == (Q(text) == q)


def test_the_check_summary_marks_rounded_values() -> None:
    """κ = 1.99999185 < κ_n = 1.99999385 were summarized "κ = 2, κ_n = 2", condition (22)
    (κ_n > λ* + κ) read as failing."""
    p = Parameters({"T_min": fmpq(1551, 10000), "kappa": fmpq(199999185, 10**8)})
    s = get_method("impulsive").summary(p)
    assert "T_min = 0.1551" in s and "κ ≈ 2" in s


def test_a_float_vector_held_as_a_list_is_shown() -> None:
    """mutation review 27 (kills shown.x_shown__mutmut_9: the raw value used as given, not
    as an array, `if f.ndim` → `if f.ndim and False`). A float vector parameter is held as a
    Python list: it has no reshape, and the table cell and the summary item raised
    AttributeError. Its entries read back as the floats held: no mark; a rounded one: "≈"."""
    p = Parameters({"v": [1.5, 2.5], "w": [0.1 + 2**-40, 2.0], "n": [1, 2]})
    assert isinstance(p["v"], list)
    assert cell(p["v"], p.float("v")) == "[1.5, 2.5]"
    assert cell(p["w"], p.float("w")) == "≈ [0.1, 2]"
    assert cell(p["n"], p.float("n")) == "[1, 2]"
    assert item("v", p["v"], p.float("v"), ".4g") == "v = [1.5, 2.5]"


@given(
    st.fractions(min_value=Fraction(-(10**12)), max_value=Fraction(10**12), max_denominator=10**15),
    st.sampled_from([".4g", ".6g", ".9g"]),
    st.sampled_from(["up", "down"]),
)
def test_a_summary_item_with_a_side_is_rounded_to_that_side(
    x: Fraction, fmt: str, side: str
) -> None:
    """A value shown with "≤" is at most the number printed, with "≥" at least it: T_max =
    2.4755274e-7 was printed "T_max ≈ 2.476e-07", above the bound (soundness trial, session
    32). A value the text shows exactly keeps "="."""
    q = Q(x)
    text = item("v", q, float(q), fmt, side)
    label, rel, num = text.split(" ", 2)
    assert label == "v"
    if rel == "=":
        assert Q(num) == q
    else:
        assert rel == ("≤" if side == "up" else "≥")
        assert (q <= Q(num)) if side == "up" else (q >= Q(num))


def test_the_impulsive_window_is_shown_on_its_safe_sides() -> None:
    """T_min rounded up, T_max down, each marked: the trial's window 7.106147e-8 … 2.4755274e-7
    (a field without a side keeps "≈")."""
    p = Parameters({"T_min": Q("7.106147e-8"), "T_max": Q("2.4755274e-7"), "kappa": Q("1.2345678")})
    s = get_method("impulsive").summary(p)
    assert s == "T_min ≤ 7.107e-08, T_max ≥ 2.475e-07, κ ≈ 1.235"


# -- mutation review 33 (session 32's checks) ----------------------------------------
def test_a_directed_bound_below_the_float_range_is_not_printed_as_zero() -> None:
    """v = 10⁻⁴⁰⁰ exactly, side "up": its 4-digit upper bound 1e-400 has no float (0.0);
    "v ≤ 0" would be false (kills H05, which returned the float text unchecked)."""
    got = shown_mod.item("v", fmpq(1, 10**400), 0.0, ".4g", "up")
    assert got != "v ≤ 0"
    assert not got.endswith("≤ 0")


def test_a_float_value_gets_no_directed_bound() -> None:
    """A float (not exact) value is marked ≈, never "≤"/"≥", which claim a bound of an exact
    value (kills H06, which let floats through _directed)."""
    assert shown_mod._directed(0.123456789, ".4g", False) is None
    got = shown_mod.item("T_max", 0.123456789, 0.123456789, ".4g", "down")
    assert "≥" not in got and "≤" not in got


# -- mutation review 33 (session 32's checks) ----------------------------------------
# side "up": the statements stay true with a larger value (an upper bound: T_min, v_max,
# λ of a decay bound, Lipschitz constants); "down": with a smaller one (T_max, α, κ_n)
SAFE = {
    "impulsive": {
        "T_min": "up",
        "T_max": "down",
        "kappa_n": "down",
        "varpi_o": "up",
        "ball_radius": "up",
    },
    "lyapunov": {
        "lambda": "up",
        "alpha": "down",
        "lambda_best": "up",
        "alpha_best": "down",
        "mu": "up",
    },
    "constrained": {"delta": "up", "v_max": "up", "v_min": "down"},
    "search-space": {"L_f": "up", "L_h": "up", "f_sup": "up"},
}


@pytest.mark.parametrize("key", sorted(SAFE))
def test_summary_fields_round_towards_their_safe_side(key: str) -> None:
    """Kills H11 (impulsive T_max "up"), H13 (lyapunov alpha "up"), H14, H15, H16: the
    summary would print "T_max ≤ …" rounded up, a window end the observer may not use."""
    sides = {f.param: f.side for f in get_method(key).summary_fields}
    for param, side in SAFE[key].items():
        assert sides[param] == side, (key, param)


def test_a_one_sided_bound_is_rounded_to_its_safe_side_in_a_table_cell() -> None:
    """The parameter table rounded to nearest: "T_max ≈ 0.608687" for a certified T_max =
    0.6086869942…, above the limit of (26b) 0.6086869942923880… (soundness trial, session
    34). With the summary field's side, a cell is rounded that way and marked ≥ / ≤."""
    from obsdesign.report.shown import cell

    t_max = Q("0.60868699429238801")
    assert cell(t_max, float(t_max)) == "≈ 0.608687"
    assert cell(t_max, float(t_max), side="down") == "≥ 0.608686"
    assert cell(t_max, float(t_max), side="up") == "≤ 0.608687"
    assert cell(Q("0.5396"), 0.5396, side="down") == "0.5396"  # shown exactly: no mark
    vec = np.array([t_max, t_max], dtype=object)
    assert cell(vec, [float(t_max)] * 2, side="down") == "≈ [0.608687, 0.608687]"


def test_the_parameter_table_takes_the_sides_of_the_methods_summary_fields() -> None:
    """render's rows use the side of each parameter's summary field (impulsive: T_max down,
    T_min up); a parameter without one keeps "≈"."""
    from obsdesign.report.model import Report
    from obsdesign.report.render import _param_rows

    p = Parameters(
        {
            "T_max": Q("0.60868699429238801"),
            "T_min": Q("0.10917512345678"),
            "kappa": Q("2.16666655"),
        }
    )
    rep = Report(
        method="impulsive", spec="", spec_file="s.toml", spec_sha256="", claims=[], parameters=p
    )
    rows = {k: v for k, v, _ in _param_rows(rep)}
    assert rows["T_max"] == "≥ 0.608686" and rows["T_min"] == "≤ 0.109176"
    assert rows["kappa"] == "≈ 2.16667"
    rep.method = "no-such-method"
    assert {k: v for k, v, _ in _param_rows(rep)}["T_max"] == "≈ 0.608687"
