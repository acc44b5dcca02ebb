"""The claim model and builder (obsdesign.certify.claim): statuses, serialization, matches."""

from __future__ import annotations

import numpy as np
from flint import fmpq

from obsdesign.certify.claim import (
    Claim,
    Claims,
    ClaimStatus,
    exact_claim,
    numerical_claim,
)
from obsdesign.certify.exact import qmat

F = fmpq


def test_status_values_and_ok():
    assert [s.value for s in ClaimStatus] == ["certified", "numerical", "failed"]
    c = exact_claim("a", "s", "r", "chk", 0, True, "d")
    assert c.status is ClaimStatus.CERTIFIED and c.ok
    assert exact_claim("a", "s", "r", "chk", 0, False, "d").ok is False
    n = numerical_claim("b", "s", "r", "chk", 0, True, "d")
    assert n.status is ClaimStatus.NUMERICAL and n.ok
    assert numerical_claim("b", "s", "r", "chk", 0, False, "d").ok is False


def test_exact_and_numerical_claim_fields():
    c = exact_claim("id1", "stmt", "ref", "check", F(1, 3), True, "det", float_ok=False)
    assert c == Claim("id1", "stmt", "ref", "check", "1/3", ClaimStatus.CERTIFIED, "det", False, {})
    assert exact_claim("i", "s", "r", "c", 0, True, "d").float_ok is None
    n = numerical_claim("id2", "stmt", "ref", "check", 0.5, False, "det")
    assert n == Claim("id2", "stmt", "ref", "check", "0.5", ClaimStatus.FAILED, "det", False, {})
    assert numerical_claim("i", "s", "r", "c", 0, True, "d").float_ok is True


def test_to_dict_and_back():
    c = exact_claim("id1", "stmt", "ref", "check", 2, True, "det", float_ok=True)
    d = c.to_dict()
    assert d == {
        "id": "id1",
        "statement": "stmt",
        "reference": "ref",
        "check": "check",
        "margin": "2",
        "status": "certified",
        "detail": "det",
        "float_ok": True,
    }
    assert isinstance(d["status"], str) and type(d["status"]) is str
    assert Claim.from_dict(d) == c
    c.extra["x"] = [1, 2]
    d = c.to_dict()
    assert d["extra"] == {"x": [1, 2]}
    d["extra"]["x"].append(3)  # a deep copy: the claim is not changed through its dict
    assert c.extra == {"x": [1, 2]}
    d = c.to_dict()
    assert Claim.from_dict(d) == c
    minimal = {
        "id": 5,
        "statement": "s",
        "reference": "r",
        "check": "c",
        "margin": 0,
        "status": "failed",
    }
    m = Claim.from_dict(minimal)
    assert m == Claim("5", "s", "r", "c", "0", ClaimStatus.FAILED, "", None, {})
    assert m.detail == "" and m.float_ok is None and m.extra == {}


def test_claims_builder():
    cs = Claims()
    a = cs.exact(id="a", statement="s", reference="r", check="c", passed=True)
    assert a.status is ClaimStatus.CERTIFIED and a.margin == "0" and a.detail == ""
    assert a.float_ok is None
    b = cs.exact(
        id="b",
        statement="s",
        reference="r",
        check="c",
        passed=False,
        margin=F(1, 2),
        detail="d",
        float_ok=True,
    )
    assert (b.status, b.margin, b.detail, b.float_ok) == (ClaimStatus.FAILED, "1/2", "d", True)
    n = cs.numerical(id="n", statement="sn", reference="rn", check="cn", passed=True)
    assert n == Claim("n", "sn", "rn", "cn", "0", ClaimStatus.NUMERICAL, "", True, {})
    n2 = cs.numerical(
        id="n2", statement="s", reference="r", check="c", passed=False, margin=3, detail="dd"
    )
    assert (n2.status, n2.margin, n2.detail) == (ClaimStatus.FAILED, "3", "dd")
    f = cs.failed(id="f", statement="s", reference="r", detail="missing")
    assert f == Claim("f", "s", "r", "presence", "0", ClaimStatus.FAILED, "missing", False, {})
    assert list(cs) == [a, b, n, n2, f]
    assert [c.id for c in cs] == ["a", "b", "n", "n2", "f"]


def test_matches_equal_adds_nothing():
    cs = Claims()
    assert cs.matches("L", [[F(1, 2)], ["-1/3"]], qmat([[0.5], [F(-1, 3)]]), "[method].L") is True
    assert cs.matches("lam", "9/10", F(9, 10), "[method].lambda") is True
    assert cs.matches("lam", 0.5, "1/2", "[method].lambda") is True
    assert cs.matches("mode", "abc", "abc", "[method].mode") is True
    assert cs.matches("xs", (1, 2), [F(1), F(2)], "[x]") is True
    assert len(cs) == 0


def test_matches_differs_adds_a_failed_claim():
    cs = Claims()
    assert (
        cs.matches(
            "L", [[F(1, 2)], [F(-1, 3)]], [[F(1, 2)], [F(-1, 3) + F(1, 10**40)]], "[method].L"
        )
        is False
    )
    (c,) = cs
    assert c == Claim(
        id="L-matches-spec",
        statement="the reported L is the one the spec fixes ([method].L)",
        reference="spec [method].L",
        check="exact equality",
        margin="0",
        status=ClaimStatus.FAILED,
        detail="the report's L differs from the spec's [method].L",
        float_ok=False,
        extra={},
    )
    assert cs.matches("lam", 0.9, "9/10", "[method].lambda") is False  # 0.9 is binary
    assert cs.matches("mode", "abc", "abd", "[method].mode") is False
    assert cs.matches("shape", [[1, 2]], [[1], [2]], "[x]") is False
    assert cs.matches("len", [1, 2], [1, 2, 3], "[x]") is False
    assert cs.matches("arr", np.array([1, 2], dtype=object), [1, 3], "[x]") is False
    assert cs.matches("scalar-vs-list", 1, [1], "[x]") is False
    # an array against a scalar, mixed float/string lists (no common string dtype)
    assert cs.matches("a1", np.array([1], dtype=object), 1, "[x]") is False
    assert cs.matches("a2", np.array([1, 2], dtype=object), 1, "[x]") is False
    assert cs.matches("a3", 1, np.array([1], dtype=object), "[x]") is False
    assert cs.matches("m1", [0.1, "1/3"], ["1/10", "1/3"], "[x]") is False
    assert cs.matches("m2", ["1/10", "1/3"], [0.1, "1/3"], "[x]") is False
    assert cs.matches("m3", (0.1, "1/3"), ("1/10", "1/3"), "[x]") is False
    assert cs.matches("m4", [0.5, "1/3"], ["1/2", "1/3"], "[x]") is True
    exact_strings = np.array(["1/10", "1/3"], dtype=object)
    assert cs.matches("m5", [0.1, "1/3"], exact_strings, "[x]") is False
    assert cs.matches("m6", exact_strings, [0.1, "1/3"], "[x]") is False
    assert [c.id for c in cs][-8:] == [
        "a1-matches-spec",
        "a2-matches-spec",
        "a3-matches-spec",
        "m1-matches-spec",
        "m2-matches-spec",
        "m3-matches-spec",
        "m5-matches-spec",
        "m6-matches-spec",
    ]
    assert [c.id for c in cs][:7] == [
        "L-matches-spec",
        "lam-matches-spec",
        "mode-matches-spec",
        "shape-matches-spec",
        "len-matches-spec",
        "arr-matches-spec",
        "scalar-vs-list-matches-spec",
    ]
    assert all(c.status is ClaimStatus.FAILED for c in cs)


def test_checked_takes_verdict_and_detail_from_a_result():
    from obsdesign.certify.psd import check_pd

    cs = Claims()
    good = cs.checked(
        id="P", statement="P ≻ 0", reference="r", check="LDLᵀ", result=check_pd(qmat([[1]]))
    )
    bad_result = check_pd(qmat([[1, 0], [0, F(-1, 10**30)]]))
    bad = cs.checked(
        id="Q", statement="Q ≻ 0", reference="r", check="LDLᵀ", result=bad_result, margin=F(1, 3)
    )
    assert good == Claim(
        "P", "P ≻ 0", "r", "LDLᵀ", "0", ClaimStatus.CERTIFIED, check_pd(qmat([[1]])).detail
    )
    assert bad_result.ok is False and bad_result.detail
    assert bad == Claim(
        "Q", "Q ≻ 0", "r", "LDLᵀ", "1/3", ClaimStatus.FAILED, bad_result.detail, None, {}
    )
    assert list(cs) == [good, bad]


def test_missing_claim_is_failed():
    from obsdesign.certify.claim import missing_claim

    assert missing_claim("P") == Claim(
        "P-present",
        "the report gives P",
        "report",
        "presence",
        "0",
        ClaimStatus.FAILED,
        "P missing",
        False,
        {},
    )
    assert missing_claim("lambda_best").ok is False
