"""Entry-by-entry comparisons of certifying checks: a forged report that changes ANY single
entry of a compared matrix or list must fail the claim that compares it.

Mutation review of session 45 (mutation testing of the certifying checks) found mutants that
survived the suite: the code is sound, but each tamper test changed one fixed entry, so a
comparison that skipped another row, column, entry or key still passed every test —

- stubborn ``gain-relation`` (X = P K) without the last row of X (S05, finding F1);
- impulsive ``Abar`` (Ā = T A T⁻¹) without entry (0, 0) (M01, F2);
- search-space ``eps-schedule`` (ε_i = γ_i/κ) without the last entry (M02, F3);
- impulsive ``lipschitz-x-blocks`` without ‖P_n‖ ≤ norm_Pn (M05, F4);
- impulsive ``T`` (T = [C; M], M from the spec) without M's last column (M06, F5);
- constrained v_min (21) with its right-hand side rounded up, not down (K11).

Each tamper here forges a report as a forger would: one exact parameter changed (its float
the nearest double of the new exact value, as ``Parameters.to_json`` writes it), every other
parameter kept (or re-derived consistently where the claim's inputs feed derived data), the
claims recomputed for the forged parameters with each failed one written "certified". Then
``api.verify`` must exit 1 and name exactly the tampered claim. The loops run over every
entry (every norm key), so that skipping any one of them is caught, not only the mutant's.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from flint import fmpq
from mpmath import iv

from obsdesign import api
from obsdesign.certify.exact import Q, qeye, qmat
from obsdesign.certify.interval import lower, upper
from obsdesign.methods.constrained import bounds as B
from obsdesign.methods.constrained.cmap import ellipsoid_map
from obsdesign.methods.impulsive.core import NORM_KEYS, blocks_from_norms
from obsdesign.params import Parameters
from obsdesign.report.model import Report
from obsdesign.sets import Box
from obsdesign.spec.models import Spec

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "specs"
STUBBORN_EX1 = SPECS / "astolfi-stubborn-example1.toml"  # X is 2 × 1
STUBBORN_EX4 = SPECS / "astolfi-stubborn-example4.toml"  # X is 4 × 2
IMPULSIVE_EX = SPECS / "schaum-impulsive-example.toml"  # M = [[-3, 1]]
SEARCHSPACE_EX = SPECS / "hernandez-garcia-example.toml"  # 12 schedule entries
TINY = fmpq(1, 2**80)

#: impulsive with ``lipschitz_x`` data (no shipped spec uses it; the plant of
#: tests/test_impulsive_soundness.py): M is free and the design takes T = I, so
#: ‖C‖ = ‖M‖ = ‖P_o‖ = ‖P_n‖ = 1 exactly
LIPSCHITZ_X = (ROOT / "tests" / "specs" / "impulsive-lipschitz-x.toml").read_text(encoding="utf-8")

Design = tuple[Spec, Report]


def _design(spec: Spec) -> Design:
    rep = api.design(spec)
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    return spec, rep


@pytest.fixture(scope="module")
def stubborn_ex1() -> Design:
    return _design(api.load_spec(STUBBORN_EX1))


@pytest.fixture(scope="module")
def stubborn_ex4() -> Design:
    return _design(api.load_spec(STUBBORN_EX4))


@pytest.fixture(scope="module")
def impulsive_ex() -> Design:
    return _design(api.load_spec(IMPULSIVE_EX))


@pytest.fixture(scope="module")
def impulsive_lipschitz_x() -> Design:
    return _design(api.load_spec_text(LIPSCHITZ_X, "impulsive-lipschitz-x.toml"))


@pytest.fixture(scope="module")
def searchspace_ex() -> Design:
    return _design(api.load_spec(SEARCHSPACE_EX))


# -- the forger ------------------------------------------------------------------------------
def _forge(rep: Report, spec: Spec, params: Parameters) -> dict[str, Any]:
    """``rep`` with ``params`` (round-tripped through the JSON form, so every float is the
    nearest double of its exact value) and the claims recomputed against ``spec`` for them,
    each failed one written "certified" (numerical ones kept): what a forger writes."""
    back, problems = Parameters.from_json(json.loads(json.dumps(params.to_json())))
    assert not problems, problems
    d = json.loads(rep.to_json())
    d["parameters"] = json.loads(json.dumps(back.to_json()))
    claims = []
    for c in api.certify(spec, back):
        cd = c.to_dict()
        if cd["status"] == "failed":
            cd["status"] = "certified"
        claims.append(cd)
    d["claims"] = claims
    return d


def _with(rep: Report, changes: dict[str, Any]) -> Parameters:
    """A copy of ``rep``'s parameters with ``changes`` (exact values)."""
    new = Parameters(dict(rep.parameters.items()))
    for k, v in changes.items():
        new[k] = v
    return new


def _verified(d: dict[str, Any], tmp_path: Path) -> tuple[int, set[str]]:
    """(exit code of ``api.verify`` on the forged report written to a file, the method's own
    failed claim ids — verify adds report-alters:<id> / report-verdict beside them)."""
    path = tmp_path / "forged.json"
    path.write_text(json.dumps(d), encoding="utf-8")
    ver = api.verify(path)
    return ver.exit_code(), {c.id for c in ver.failed if not c.id.startswith("report-")}


def _entries(X: np.ndarray) -> Iterator[tuple[int, ...]]:
    return (tuple(int(i) for i in ix) for ix in np.ndindex(*X.shape))


def _tamper_each_entry(
    design: Design, key: str, claim: str, tmp_path: Path, delta: fmpq = TINY
) -> None:
    """For every entry of the exact parameter ``key``: that entry + ``delta`` alone, forged,
    must fail verify (exit 1) with exactly ``{claim}`` failed. Lists every entry that did not."""
    spec, rep = design
    X0 = np.array(rep.parameters[key], dtype=object, copy=True)
    assert X0.size > 1
    missed = []
    for ix in _entries(X0):
        X = X0.copy()
        X[ix] = Q(X[ix]) + delta
        got = _verified(_forge(rep, spec, _with(rep, {key: X})), tmp_path)
        if got != (1, {claim}):
            missed.append((ix, got))
    assert not missed, f"{key} entries whose change did not fail {claim!r} alone: {missed}"


@pytest.mark.parametrize("name", ["stubborn_ex1", "stubborn_ex4", "impulsive_ex", "searchspace_ex"])
def test_an_untampered_forgery_verifies(
    name: str, request: pytest.FixtureRequest, tmp_path: Path
) -> None:
    """The forger itself changes nothing else: with no tamper its report verifies (exit 0), so
    the exit 1 of each tamper below is the tampered entry's doing (and under a mutant that
    skips the entry, the forgery verifies)."""
    spec, rep = request.getfixturevalue(name)
    assert _verified(_forge(rep, spec, _with(rep, {})), tmp_path) == (0, set())


# -- F1: stubborn gain-relation, X = P K -----------------------------------------------------
@pytest.mark.parametrize("name", ["stubborn_ex1", "stubborn_ex4"])
def test_gain_relation_fails_for_every_entry_of_X(
    name: str, request: pytest.FixtureRequest, tmp_path: Path
) -> None:
    """Mutation review 45, F1 (mutant S05: the comparison X = P K skipped X's last row; the only
    tamper changed X[0, 0]). Every entry of X + 2⁻⁸⁰ (the exact value and its float) fails
    ``gain-relation`` alone: Example 1 (X 2 × 1: the last row) and Example 4 (X 4 × 2: the
    last column too)."""
    _tamper_each_entry(request.getfixturevalue(name), "X", "gain-relation", tmp_path)


# -- F2: impulsive Abar, Ā = T A T⁻¹ ---------------------------------------------------------
def test_abar_fails_for_every_entry(impulsive_ex: Design, tmp_path: Path) -> None:
    """Mutation review 45, F2 (mutant M01: Ā = T A T⁻¹ compared without entry (0, 0); the only
    tamper changed Ā[1, 1]). Every entry of Ā + 2⁻⁸⁰ fails ``Abar`` alone (the window's claims
    use T A T⁻¹ computed from T, not the reported Ā)."""
    _tamper_each_entry(impulsive_ex, "Abar", "Abar", tmp_path)


# -- F5: impulsive T = [C; M], M from the spec -----------------------------------------------
def test_T_fails_for_every_entry(impulsive_ex: Design, tmp_path: Path) -> None:
    """Mutation review 45, F5 (mutant M06: T's M rows compared without M's last column; the
    only M tamper changed T[1, 0]). Every entry of T + 2⁻⁸⁰ — the C row and the M row, each
    column — fails ``T`` alone (the spec gives C and M = [[-3, 1]]; a T that is not [C; M]
    stops the window's claims, so a skipped entry would show as a failed ``Abar`` instead)."""
    _, rep = impulsive_ex
    assert rep.parameters["T"].shape == (2, 2)
    _tamper_each_entry(impulsive_ex, "T", "T", tmp_path)


def test_a_report_designed_for_another_M_fails_T(impulsive_ex: Design, tmp_path: Path) -> None:
    """Mutation review 45, F5: a report designed for M = [[-3, 1.000001]] — every parameter
    consistent with that other observer, the claims recomputed against the spec's
    M = [[-3, 1]] — must fail ``T`` (the difference is in M's last column only)."""
    spec, rep = impulsive_ex
    text = rep.spec
    assert text.count("M = [[-3, 1]]") == 1
    _, other = _design(api.load_spec_text(text.replace("M = [[-3, 1]]", "M = [[-3, 1.000001]]")))
    T = other.parameters["T"]
    assert T[1, 0] == rep.parameters["T"][1, 0] and T[1, 1] == Q("1.000001")
    d = _forge(rep, spec, Parameters(dict(other.parameters.items())))
    assert _verified(d, tmp_path) == (1, {"T"})


# -- F4: impulsive lipschitz-x-blocks, one per norm key --------------------------------------
def test_lipschitz_x_blocks_fails_for_each_understated_norm(
    impulsive_lipschitz_x: Design, tmp_path: Path
) -> None:
    """Mutation review 45, F4 (mutant M05: ‖P_n‖ ≤ norm_Pn not checked; dropping any norm key but
    norm_C survived, the only tamper lowered norm_C). For each of norm_C, norm_M, norm_Po,
    norm_Pn: the bound set to 1 − 2⁻⁸⁰ below the true norm 1 (T = I), the derived ℓ_on, ℓ_no
    re-derived from the lowered bounds and λ*_on, λ*_no moved with them (u = λ* − ℓ kept), so
    the forgery is consistent but for the understated norm: ``lipschitz-x-blocks`` alone fails.
    """
    spec, rep = impulsive_lipschitz_x
    p = rep.parameters
    assert (p["T"] == qeye(2)).all()  # so each of the four norms is exactly 1
    ell = Q("0.005")
    m, n = 1, 2
    missed = []
    for key in NORM_KEYS:
        nb = {k: Q(p[k]) for k in NORM_KEYS}
        assert nb[key] >= 1
        nb[key] = 1 - TINY
        data = blocks_from_norms(ell, nb, m, n)
        changes: dict[str, Any] = dict(nb)
        changes["ell_on"], changes["ell_no"] = data.ell_on, data.ell_no
        changes["lambda_on"] = Q(p["lambda_on"]) - Q(p["ell_on"]) + data.ell_on
        changes["lambda_no"] = Q(p["lambda_no"]) - Q(p["ell_no"]) + data.ell_no
        got = _verified(_forge(rep, spec, _with(rep, changes)), tmp_path)
        if got != (1, {"lipschitz-x-blocks"}):
            missed.append((key, got))
    assert not missed, f"understated norms not failing lipschitz-x-blocks alone: {missed}"


# -- F3: search-space eps-schedule, ε_i = γ_i/κ ----------------------------------------------
def test_eps_schedule_fails_for_every_entry(searchspace_ex: Design, tmp_path: Path) -> None:
    """Mutation review 45, F3 (mutant M02: ε_i = γ_i/κ never compared for the last entry; the
    only tamper changed ε_5). Every entry of the 12-entry schedule + 2⁻⁸⁰ — the first and the
    last, ε₁₁ = γ⋆/κ included (``eps-star`` checks the reported ε⋆, not the schedule) — fails
    ``eps-schedule`` alone."""
    _, rep = searchspace_ex
    assert len(rep.parameters["eps_schedule"]) == 12
    _tamper_each_entry(searchspace_ex, "eps_schedule", "eps-schedule", tmp_path)


# -- K11: constrained v_min (21), the right-hand side rounded down ---------------------------
def test_v_min_condition_rounds_its_right_hand_side_down() -> None:
    """Mutation review 45, K11 (mutant: the rhs r(1 + √ε_min) of (21) enclosed upward survived;
    through design/verify no tight case was found, as κ carries slack). By hand, with v = 0 so
    that the left side is exact: the ellipsoid map |x|² ≤ 1 (r = 1) over X = {2} gives
    (√4 + 0)² = 4 on the left. ε_min = 9: r(1 + 3) = 4, (21) holds (≤, exact at the
    boundary). ε_min = 9 − 2⁻²⁰⁰: the right side 1 + √ε_min < 4 exactly, so (21) fails — but
    its 113-bit upper enclosure is 4, so only the downward rounding of the rhs refuses it."""
    em = ellipsoid_map(qeye(1), 1)
    P = qmat([[1]])  # = P⁻¹: V(e) = e², κ ≥ 1 (unused: v = 0)
    X = Box(np.array([Q(2)], dtype=object), np.array([Q(2)], dtype=object))
    eps = 9 - fmpq(1, 2**200)

    def rhs(r: Any, e: Any) -> Any:
        return r * (1 + iv.sqrt(e))

    # the premise: the enclosure of the false rhs reaches the exact lhs 4 from above only
    assert lower(rhs, fmpq(1), eps) < 4 <= upper(rhs, fmpq(1), eps)
    assert B.v_min_condition(em, P, P, X, Q(9), fmpq(0))
    assert not B.v_min_condition(em, P, P, X, eps, fmpq(0))
