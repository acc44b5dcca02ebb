"""The ``constrained`` method on the paper's Section 5 example (paper 000): design, verify,
Table 1, bad input."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from flint import fmpq
from typer.testing import CliRunner

from obsdesign import api
from obsdesign.api import load_spec_text
from obsdesign.certify.claim import ClaimStatus
from obsdesign.cli import app
from obsdesign.errors import InfeasibleError, SpecError
from obsdesign.report import Report

SEC5 = "constrained-redesign-sec5.toml"


@pytest.fixture(scope="module")
def sec5_report():
    return api.design(Path(__file__).resolve().parents[1] / "specs" / SEC5)


def test_sec5_design_certified(sec5_report):
    rep = sec5_report
    bad = [c.id for c in rep.claims if c.status != ClaimStatus.CERTIFIED]
    assert not bad
    p = rep.parameters
    # the paper's P and P⁻¹ (printed to 3 digits)
    P = p.float("P")
    np.testing.assert_array_equal(np.round(P / 1e5, 3), [[1.259, 1.319], [1.319, 1.381]])
    np.testing.assert_array_equal(np.round(np.linalg.inv(P), 3), [[0.039, -0.037], [-0.037, 0.036]])
    for k in ("P", "rho", "mu", "gamma", "delta", "eps_min", "eps_max", "v_max", "v_min", "theta"):
        assert k in p.to_json()
    assert p["eps_min"] == fmpq(1, 100)
    assert p["rho"] == fmpq(955, 1000)
    # numbers of this design (ρ = λ = 0.955, X = [-1, 1]², D = [-3, 3], X̂ = outer box of C_min)
    assert p.float("v_max") == pytest.approx(2659567.3, rel=1e-7)  # exact: vertices of X̂ − X
    assert p.float("v_min") == pytest.approx(0.90753137, rel=1e-7)
    assert p.float("eps_max") == pytest.approx(140098, rel=1e-5)
    # δ = 2√ε_max ≈ 748.6. The issue expected ≈ 637: that is 2·(largest single-coordinate
    # violation over X̂_max); with the Euclidean |c| of (16) both coordinates peak together, so
    # C_max ⊇ X̂_max needs ε_max ≈ 1.4·10⁵ and δ ≈ 749.
    assert p.float("delta") == pytest.approx(748.59, rel=1e-4)
    lam_min = np.linalg.eigvalsh(P).min()
    assert p.float("gamma") <= lam_min / p.float("delta_sq")
    assert p.float("gamma") == pytest.approx(2.3965e-5, rel=1e-4)
    # θ (22) with the certified γ; with the paper's γ = 17 it would be ≈ 1.56·10⁹ (issue: ≈1.5·10⁹)
    theta = int(p["theta"])
    assert theta == pytest.approx(1.10977e15, rel=1e-5)
    assert (p.float("v_max") - p.float("v_min")) / (17 * 1e-4) == pytest.approx(1.564e9, rel=1e-3)


def test_sec5_verify_roundtrip(sec5_report):
    rep2, problems = Report.from_dict(sec5_report.to_dict())
    assert not problems
    ver = api.verify(rep2)
    assert ver.exit_code() == 0
    assert ver.status_counts()["failed"] == 0


def test_sec5_verify_rejects_tampered_theta(sec5_report):
    d = sec5_report.to_dict()
    d["parameters"]["theta"] = 1000.0
    d["parameters"]["exact"]["theta"] = "1000"
    rep2, _ = Report.from_dict(d)
    ver = api.verify(rep2)
    failed = {c.id for c in ver.claims if c.status == ClaimStatus.FAILED}
    assert "theta-covers" in failed


def test_sec5_table1(specs_dir):
    """Table 1. Unmodified row: x̂¹ = 22.582 reproduced at the printed precision; x̂² = 21.610486
    is 21.610 at the printed precision, NOT the paper's 21.611 (1.4e-5 below the rounding
    boundary; the paper may have rounded 21.6105 twice, a guess). Modified rows: the literal
    reading of (20), (23) with the squared box map (19) and the paper's γ = 17 diverges (each
    step grows like the cube of the violation), so the printed 1.195/1.238, 6.602/4.783 (θ_m = 10)
    and 9.795/8.366, 11.960/10.358 (θ_m = 3) are NOT reproduced; we assert what we get."""
    res = api.simulate(specs_dir / SEC5)
    info = res.info
    assert info["unmodified: sup_k |x̂_k|"] == "[22.5818, 21.6105]"  # paper: 22.582 / 21.611
    tr = res.extra["traces"]["unmodified"]
    sup = tr.sup_k()
    assert round(sup[0], 3) == 22.582  # the paper's, at its precision
    assert round(sup[1], 3) == 21.610 != 21.611  # not the paper's 21.611
    assert sup[1] == pytest.approx(21.610486, abs=1e-6)
    assert "UNCERTIFIED" in info["gamma (simulation)"]
    for tm in (10, 3):
        t = res.extra["traces"][f"modified θ_m={tm}"]
        assert t.sup_k()[0] > 1e7  # diverges (paper: 1.195 for θ_m = 10, 9.795 for θ_m = 3)
        assert info[f"modified θ_m={tm}: x̂_k in X̂ for all k ≥ 1"] is False
    # naive saturation (29) with r = 2: stuck at (2, −2) without disturbance
    sat = res.extra["traces"]["saturated r=[2]"].xhat
    np.testing.assert_array_equal(sat[1:151], np.tile([2.0, -2.0], (150, 1)))
    np.testing.assert_array_equal(sat[-1], [2.0, -2.0])


def test_sec5_certified_gamma_simulation(specs_dir):
    """With the certified γ the refining never increases V (Lemma 3) and lowers the peak a little."""
    res = api.simulate(specs_dir / SEC5, options={"gamma": "2.3965e-05"})
    assert "certified" in res.info["gamma (simulation)"]
    t10 = res.extra["traces"]["modified θ_m=10"]
    np.testing.assert_allclose(t10.sup_k(), [21.022, 19.986], atol=1e-3)
    assert float(res.info["modified θ_m=10: max relative V increase over a refining step"]) <= 1e-9


TSPECS = Path(__file__).resolve().parent / "specs"
BOX = 'type = "box"\nlower = [-1.1, -1.1]\nupper = [1.1, 1.1]'


def spec_text(name: str = "box") -> str:
    """A shared test spec, ``tests/specs/constrained-<name>.toml``."""
    return (TSPECS / f"constrained-{name}.toml").read_text(encoding="utf-8")


def variant(name: str = "box", *, add: str = "", c: str | None = None, replace: tuple = ()) -> str:
    """A test spec with ``add`` lines put into [method], the [method.c] body replaced by ``c``
    and each (old, new) of ``replace`` applied (each old text must occur)."""
    text = spec_text(name)
    if add:
        text = text.replace('key = "constrained"\n', f'key = "constrained"\n{add}\n', 1)
    if c is not None:
        text = re.sub(r"\[method\.c\]\n.*?\n\n", f"[method.c]\n{c}\n\n", text, count=1, flags=re.S)
    for old, new in replace:
        assert old in text, old
        text = text.replace(old, new, 1)
    return text


def _spec(extra: str = "", c: str = BOX):
    return load_spec_text(variant(add=extra, c=c), "bad.toml")


def test_bad_eps_order():
    with pytest.raises(SpecError) as e:
        _spec("eps_max = 0.005")
    assert "method.eps_max" in str(e.value) and "bad.toml" in str(e.value)


def test_bad_gamma_above_bound_names_the_bound():
    sp = _spec("gamma = 17")
    with pytest.raises(InfeasibleError) as e:
        api.design(sp)
    assert "2.3965e-05" in str(e.value) and "(24)" in str(e.value)
    assert "× too large" in str(e.value)


def test_gamma_just_above_its_bound_says_by_how_much() -> None:
    """γ a millionth above the largest certified γ: the message said "1× too large"; now the
    relative excess (random-spec fuzzer)."""
    from obsdesign.certify.exact import Q
    from obsdesign.methods.constrained.design import _over

    assert _over(Q("1.000001"), 1) == "1e-06 (relative) above it"
    assert _over(17, Q("2.3965e-05")) == "7.09e+05× too large"
    # the refusal says which bound: the relative excess is over the certified γ, which lies
    # below (24) itself ("above it" read as the excess over (24); session 43)
    sp = _spec("gamma = 0.00002396505031790019468897047")
    with pytest.raises(InfeasibleError) as e:
        api.design(sp)
    assert "(relative) above that certified γ" in str(e.value), str(e.value)


def test_gamma_uncertified_is_failed_claim():
    sp = _spec("gamma = 17\ngamma_uncertified = true")
    rep = api.design(sp)
    st = {c.id: c.status for c in rep.claims}
    assert st["gamma-bound"] == ClaimStatus.FAILED
    assert rep.exit_code() == 1


def test_bad_nonconvex_c():
    with pytest.raises(SpecError) as e:
        _spec(c='type = "ellipsoid"\nQ = [[1, 0], [0, -1]]\nr = 2')
    assert "method.c.Q" in str(e.value) and "convex" in str(e.value)
    with pytest.raises(SpecError) as e:
        _spec(c='type = "sine"')
    assert "method.c.type" in str(e.value)


def test_bad_P_not_positive_definite():
    text = variant(
        replace=[("lambda = 0.955\nrho = 0.955", "P = [[1, 2], [2, 1]]\nrho = 0.9\nmu = 1")]
    )
    with pytest.raises(SpecError) as e:
        load_spec_text(text, "bad.toml")
    assert "method.P" in str(e.value)


def test_bad_xhat_not_containing_x():
    """X̂ ⊉ X (hence ⊉ C_min): the inclusion claim fails, exit 1 with the reason."""
    rep = api.design(_spec('Xhat = "small"'))
    st = {c.id: c for c in rep.claims}
    assert st["Cmin-in-Xhat"].status == ClaimStatus.FAILED
    assert rep.exit_code() == 1


def test_bad_c_not_containing_x():
    rep = api.design(_spec(c='type = "box"\nlower = [-0.9, -0.9]\nupper = [0.9, 0.9]'))
    st = {c.id: c for c in rep.claims}
    assert st["X-in-C0"].status == ClaimStatus.FAILED


def test_cli_exit_codes(write_spec):
    r = CliRunner()
    p = write_spec(variant(add="eps_max = 0.001"))
    out = r.invoke(app, ["design", str(p)])
    assert out.exit_code == 2 and "eps_max" in out.output
    p = write_spec(variant(add="gamma = 17"), "g.toml")
    out = r.invoke(app, ["design", str(p)])
    assert out.exit_code == 1 and "Traceback" not in out.output


def test_ellipsoid_and_polytope_maps_design():
    for c in (
        'type = "ellipsoid"\nQ = [[1, 0], [0, 1]]\nr = 2.5',
        'type = "polytope"\nG = [[1, 0], [0, 1], [-1, 0], [0, -1], [1, 1]]\nh = [1.1, 1.1, 1.1, 1.1, 2.1]',
    ):
        rep = api.design(_spec(c=c))
        bad = [(x.id, x.detail) for x in rep.claims if x.status != ClaimStatus.CERTIFIED]
        assert not bad, bad
        assert int(rep.parameters["theta"]) > 0


def test_remark2_theta_zero():
    """A contracting observer with a small disturbance and a generous C_min: θ = 0 (Remark 2)."""
    text = spec_text("fast")
    rep = api.design(load_spec_text(text, "r2.toml"))
    assert int(rep.parameters["theta"]) == 0
    assert any("Remark 2" in n for n in rep.notes)
    assert rep.exit_code() == 0


def test_large_box_uses_closed_forms():
    """n = 13: 2¹³ vertices exceed the vertex budget; the per-face closed forms keep it fast."""
    from test_constrained_properties import Case, random_spec

    sp, _ = random_spec(Case(n=13, seed=13, r_pad=0.5, eps_min=0.05, wbound=0.1, rad=0.5))
    rep = api.design(sp)
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    assert any("upper bound" in n for n in rep.notes)


def test_v_max_breve_and_tampered_gamma(specs_dir):
    text = (specs_dir / SEC5).read_text()
    text = text.replace(
        "[method]",
        '[sets.X0]\ntype = "box"\nlower = [-1, -1]\nupper = [-0.9, -0.9]\n'
        '[sets.Xhat0]\ntype = "box"\nlower = [0.9, 0.9]\nupper = [1, 1]\n[method]',
        1,
    ).replace("eps_min = 0.01", 'eps_min = 0.01\nX0 = "X0"\nXhat0 = "Xhat0"')
    rep = api.design(load_spec_text(text, "breve.toml"))
    assert rep.exit_code() == 0
    # v̆_max = V(e0,max) + μ·9/(1 − ρ) ≈ 2.11e6 + 4.9e6 > v_max: θ̆ = θ (the paper's caveat)
    assert rep.parameters.float("v_max_breve") == pytest.approx(7.008e6, rel=1e-3)
    assert int(rep.parameters["theta_breve"]) == int(rep.parameters["theta"])
    d = rep.to_dict()
    d["parameters"]["gamma"] = 17.0
    d["parameters"]["exact"]["gamma"] = "17"
    ver = api.verify(Report.from_dict(d)[0])
    failed = {c.id for c in ver.claims if c.status == ClaimStatus.FAILED}
    assert "gamma-bound" in failed and ver.exit_code() == 1


def test_X0_must_be_a_box_or_polytope(specs_dir):
    """An ellipsoid X0 is refused with the key named and the set's kind in plain English."""
    text = (specs_dir / SEC5).read_text()
    text = text.replace(
        "[method]",
        '[sets.X0]\ntype = "ellipsoid"\nE = [[1, 0], [0, 1]]\n[method]',
        1,
    ).replace("eps_min = 0.01", 'eps_min = 0.01\nX0 = "X0"')
    with pytest.raises(SpecError, match=r"\[method\.X0\].*\[sets\.X0\] is an ellipsoid"):
        load_spec_text(text, "x0.toml")


@pytest.mark.parametrize(
    "old, new, key",
    [
        # a 1-D box [-1, 1] for the 2-state plant: numpy broadcast it over both coordinates
        # and v_min = 1.027 was certified where the 2-D box gives 0.908 (re-check trial,
        # session 41: a false certificate)
        ("lower = [-1, -1]\nupper = [1, 1]", "dim = 1\nlower = [-1]\nupper = [1]", "X"),
        (
            "lower = [-1, -1]\nupper = [1, 1]",
            "dim = 3\nlower = [-1, -1, -1]\nupper = [1, 1, 1]",
            "X",
        ),
        (
            'type = "box"\nlower = [-1, -1]\nupper = [1, 1]',
            'type = "polytope"\ndim = 1\nG = [[1], [-1]]\ng = [1, 1]',
            "X",
        ),
    ],
)
def test_a_set_of_another_dimension_than_the_state_is_refused(specs_dir, old, new, key):
    """X, X̂, X0 and X̂0 are sets of states: one of another dimension (given with dim) is
    bad input naming the key, not a design on a broadcast set (or exit 3)."""
    text = (specs_dir / SEC5).read_text()
    assert text.count(old) >= 1
    bad = text.replace(old, new, 1)
    with pytest.raises(
        SpecError, match=rf"\[method\.{key}\] expected a set of the state dimension 2"
    ):
        load_spec_text(bad, "dim.toml")


def test_sec5_max_norm_matches_issue_estimate(specs_dir):
    """With |c| the max-norm, C_min/C_max are boxes, v_min has an exact closed form, and
    δ = 643.47, γ = 3.2434e-5 (the issue's estimate: δ ≈ 637, γ ≈ 3.3e-5)."""
    text = (
        (specs_dir / SEC5)
        .read_text()
        .replace('type = "box"\nlower = [-1.1', 'type = "box"\nnorm = "max"\nlower = [-1.1')
    )
    rep = api.design(load_spec_text(text, "max.toml"))
    assert rep.exit_code() == 0
    p = rep.parameters
    assert p.float("delta") == pytest.approx(643.47, rel=1e-4)
    assert p.float("gamma") == pytest.approx(3.24344e-5, rel=1e-5)
    assert p.float("v_min") == pytest.approx(1.0270701, rel=1e-7)
    assert any("exact closed form" in n for n in rep.notes)


def test_parse_simulate_returns_options_and_leaves_the_spec(specs_dir):
    from obsdesign.methods.constrained.options import SimOptions

    sp = api.load_spec(specs_dir / SEC5)
    so = sp.simulate.options
    assert isinstance(so, SimOptions)
    assert so.theta_m == [10, 3] and so.gamma == 17
    np.testing.assert_array_equal(so.saturation_r, [2.0])
    assert not hasattr(sp.options, "sim")
    m = api.method("constrained")
    again = m.parse_simulate(sp.simulate.table, sp)
    assert again == so and sp.simulate.options is so


def test_simulate_options_validated_centrally(specs_dir, tmp_path):
    m = api.method("constrained")
    assert m.parse_sim_options({"theta_m": "10,3", "gamma": "17"}) == {
        "theta_m": "10,3",
        "gamma": 17.0,
    }
    r = CliRunner()
    spec = str(specs_dir / SEC5)
    out = r.invoke(app, ["simulate", spec, "--option", "thetam=3"])
    assert out.exit_code == 2 and "theta_m" in out.output
    out = r.invoke(app, ["simulate", spec, "--option", "gamma=abc"])
    assert out.exit_code == 2 and "gamma" in out.output
    out = r.invoke(app, ["simulate", spec, "--option", "theta_m=1,x"])
    assert out.exit_code == 2 and "theta_m" in out.output
    # θ_m = 10³⁰ ran past 120 s with memory growing (CLI fuzzer): the total is bounded first;
    # 300 samples × 333,333 steps is within 10⁸, one more step per sample is not
    out = r.invoke(app, ["simulate", spec, "--option", "theta_m=1000000000000000000000000000000"])
    assert out.exit_code == 2 and "above 100,000,000 steps in all" in out.output
    out = r.invoke(app, ["simulate", spec, "--option", "theta_m=333334"])
    assert out.exit_code == 2 and "steps in all" in out.output
    res = api.simulate(specs_dir / SEC5, options={"theta_m": "2", "saturation_r": "3"})
    assert set(res.extra["traces"]) == {"unmodified", "modified θ_m=2", "saturated r=[3]"}


def test_old_spelling_of_f_h_in_method_is_refused():
    for key in ("f", "h"):
        text = variant(add=f'{key} = ["x2", "x1"]')
        with pytest.raises(SpecError) as e:
            load_spec_text(text, "old.toml")
        assert f"method.{key}" in str(e.value) and "[system]" in str(e.value)


def test_linear_observer_needs_A_and_C():
    text = variant(replace=[("A = [[0, 1], [1, 0]]\n", "")])
    with pytest.raises(SpecError) as e:
        load_spec_text(text.replace("[system]\n", '[system]\nstates = ["x1", "x2"]\n'), "a.toml")
    assert "system.A" in str(e.value)


def test_rate_tol_below_float_resolution_is_a_spec_error():
    """λ searched (no ``lambda``) with rate_tol = 10⁻¹⁷ below the float resolution of λ ≈ 0.95:
    a spec error naming [method.rate_tol] (was: a failed bracket claim, exit 1)."""
    text = variant(replace=(("lambda = 0.955\nrho = 0.955\n", "rate_tol = 1e-17\n"),))
    with pytest.raises(SpecError) as e:
        api.design(load_spec_text(text, "bad.toml"))
    assert "method.rate_tol" in str(e.value) and "bad.toml" in str(e.value)


#: the independent simulate review's random spec: w = (d, v) inside D, θ = 704,498 spent in
#: full, x̂_k ∈ X̂ for every k
R2 = """[system]
time = "discrete"
A = [[0.6, 0.2], [-0.1, 0.5]]
C = [[1, 0], [0, 1]]
Bd = [[1, 0], [0, 1]]
[sets.X]
type = "box"
lower = [-1, -1]
upper = [1, 1]
[method]
key = "constrained"
L = [[0, -0.4], [0.5, -0.1]]
lambda = 0.9
X = "X"
eps_min = 0.04
[method.c]
type = "box"
lower = [-1.1, -1.1]
upper = [1.1, 1.1]
[method.D]
lower = [-0.1, -0.1, -0.5, -0.5]
upper = [0.1, 0.1, 0.5, 0.5]
[simulate]
horizon = 60
x0 = [0.6, -0.6]
xhat0 = [-1.2, 1.2]
seed = 4
[simulate.disturbance]
kind = "uniform"
bound = 0.1
[simulate.noise]
kind = "uniform"
bound = 0.5
"""


def test_simulate_says_when_a_run_is_outside_the_premises_of_theorem_1(tmp_path) -> None:
    """Noise outside D, a refining budget θ_m < θ spent at some sample, and a plant leaving X
    break the premises of (25b): simulate printed "x̂_k in X̂ for all k ≥ 1: False" with no
    word of why (independent simulate review). Inside D with a budget never spent: "hold",
    no warning."""
    p = tmp_path / "r2.toml"

    def run(text: str, **options: str) -> tuple[str, str]:
        p.write_text(text)
        info = api.simulate(p, options=options or None).info
        return info["premises of Theorem 1 (25b)"], " ".join(info.get("warnings", []))

    premises, said = run(R2)
    assert premises == "hold" and said == ""
    premises, said = run(R2.replace("bound = 0.5", "bound = 0.6"))
    assert premises.startswith("w_k = (d_k, v_k) leaves D at k = ")
    assert "outside the premises of the guarantee x̂_k ∈ X̂" in said
    # a sample the run never uses (w_60 at the horizon: x̂_60 comes from w_59) breaks no
    # premise; the one before it does (simulate-correctness trial, session 25)
    for k, ok in ((60, True), (59, False)):
        last = R2.replace(
            'kind = "uniform"\nbound = 0.5\n',
            f'kind = "windows"\nwindows = [{{ start = {k}, stop = {k}, value = [3, 0] }}]\n',
        )
        premises, said = run(last)
        assert (premises == "hold") is ok, premises
        assert ok or premises.startswith(f"w_k = (d_k, v_k) leaves D at k = {k} (1 of 60 samples")
    # θ_m = 0 binds only where a sample needed refining (it was flagged always)
    premises, said = run(R2, theta_m="0")
    assert premises == "θ_m = 0 < θ = 704,498 steps, all spent at some sample"
    sec5 = (Path(__file__).resolve().parents[1] / "specs" / SEC5).read_text()
    quiet = sec5.replace("xhat0 = [1, 1]", "xhat0 = [-1, -1]").replace("gamma = 17\n", "")
    quiet = quiet.replace(
        'kind = "windows"\nwindows = [{ start = 151, stop = 153, value = [3] }]', 'kind = "zero"'
    )
    assert "xhat0 = [-1, -1]" in quiet and "x0 = [-1, -1]" in quiet  # x̂0 = x0, no noise
    premises, said = run(quiet, theta_m="0,10")
    assert premises == "hold" and said == "", premises
    premises, said = run(R2, theta_m="1")
    assert premises == "θ_m = 1 < θ = 704,498 steps, all spent at some sample" and premises in said
    premises, said = run(
        R2.replace("lower = [-1, -1]\nupper = [1, 1]", "lower = [-0.5, -0.5]\nupper = [1, 1]")
    )
    assert "the plant leaves X at k = 0 (Assumption 1)" in premises and premises in said


def test_simulate_with_a_report_missing_a_parameter_names_the_report(tmp_path) -> None:
    """simulate --report whose parameters lack theta: a one-line InputError naming the
    report file (it said "report: …")."""
    import json

    from obsdesign.errors import InputError

    p = tmp_path / "r2.toml"
    p.write_text(R2)
    d = api.design(api.load_spec(p)).to_dict()
    del d["parameters"]["theta"]
    d["parameters"].get("exact", {}).pop("theta", None)
    rp = tmp_path / "r.json"
    rp.write_text(json.dumps(d))
    with pytest.raises(InputError) as e:
        api.simulate(p, report=rp)
    assert str(e.value) == f"{rp}: parameter 'theta' is missing"


def test_a_tiny_eps_min_is_a_spec_error_naming_it() -> None:
    """eps_min = 1e-300 makes θ ≈ 10⁶¹¹ (eq. (22)), beyond a report's float view: exit 2
    naming [method.eps_min] and θ's size (it was exit 4 "the spec's numbers are too large",
    naming neither file nor key: review 19). eps_min = 1e-100 still designs (θ ≈ 10²⁰⁷)."""
    tiny = variant(replace=(("eps_min = 0.01", "eps_min = 1e-300"),))
    with pytest.raises(SpecError) as e:
        api.design(load_spec_text(tiny, "tiny.toml"))
    msg = str(e.value)
    assert "tiny.toml: [method.eps_min]" in msg and "θ ≈ 10^" in msg and e.value.exit_code == 2
    ok = api.design(load_spec_text(variant(replace=(("eps_min = 0.01", "eps_min = 1e-100"),))))
    assert ok.exit_code() == 0 and float(ok.parameters.float("theta")) > 1e200


def test_a_parameter_beyond_the_float_range_is_named() -> None:
    """A huge eps_min (1e308) puts δ² beyond the float range: exit 4 naming the parameter
    ('delta_sq'), not only "the spec's numbers are too large"."""
    from obsdesign.errors import InconclusiveError

    huge = variant(replace=(("eps_min = 0.01", "eps_min = 1e308"),))
    with pytest.raises(InconclusiveError, match="parameter 'delta_sq'"):
        api.design(load_spec_text(huge, "huge.toml")).to_dict()


def test_simulate_names_an_estimate_that_starts_outside_xhat(tmp_path) -> None:
    """x̂_0 ∉ X̂ breaks Corollary 1's premise: simulate printed "premises …: hold" beside
    "x̂_k in X̂ for all k ≥ 1: False" for x̂_0 = (10⁶, −10⁶) (independent simulate review)."""
    p = tmp_path / "far.toml"
    p.write_text(R2.replace("xhat0 = [-1.2, 1.2]", "xhat0 = [1e6, -1e6]"))
    info = api.simulate(p).info
    premises = info["premises of Theorem 1 (25b)"]
    assert premises.startswith("the estimate starts outside X̂ (x̂_0 ∉ X̂")
    assert premises in " ".join(info["warnings"])


def test_simulate_time_limit_stops_a_run_with_exit_3(tmp_path, monkeypatch, slow_clock) -> None:
    """``[simulate] time_limit`` (and ``--option time_limit``) bound a constrained simulation:
    θ_m ≤ θ may be astronomically large (θ_m = 10⁵ ran past 120 s; review). Past the limit the
    run stops with a SolverError naming the key, the observer and the sample; an unknown key
    before this change, the key is now accepted, and a value below 1 ms (the option's bound)
    is exit 2."""
    from obsdesign.errors import SolverError

    p = tmp_path / "tl.toml"
    p.write_text(R2.replace("seed = 4", "seed = 4\ntime_limit = 999"))
    slow_clock()
    with pytest.raises(SolverError, match=r"not finished within 999 s \(\[simulate\] time_limit\)"):
        api.simulate(p)
    p.write_text(R2)
    slow_clock()  # every look at the clock is 1000 s later
    with pytest.raises(SolverError, match="the unmodified observer runs at sample 0 of 60"):
        api.simulate(p, options={"time_limit": "1000.5", "theta_m": "3"})
    slow_clock()
    with pytest.raises(SolverError, match="the plant at sample 0 of 60"):  # its loop too
        api.simulate(p, options={"time_limit": "999", "theta_m": "3"})
    monkeypatch.undo()
    res = api.simulate(p, options={"time_limit": "1000.5", "theta_m": "3"})
    assert res.info["modified θ_m=3: steps (total, max per sample)"]
    for bad in ("0", "0.0009", "1e-9"):
        p.write_text(R2.replace("seed = 4", f"seed = 4\ntime_limit = {bad}"))
        with pytest.raises(SpecError, match=r"\[simulate\.time_limit\]"):
            api.simulate(p)


# -- mutation review 2026-11-27 (constrained/claims.py): conditions no test decided ----------
def _mr_design(text: str) -> Report:
    rep = api.design(load_spec_text(text, "t.toml"))
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    return rep


def _mr_failed(rep: Report, *, drop_exact: tuple = (), **new: fmpq) -> dict:
    """Recomputed claims of ``rep`` with parameters replaced (exact string and float) and the
    exact strings of ``drop_exact`` removed (float kept): {claim id: status}, ``report-*``
    (stored-vs-recomputed) claims left out."""
    from obsdesign.certify.exact import qstr

    d = rep.to_dict()
    for k, v in new.items():
        d["parameters"]["exact"][k] = qstr(v)
        d["parameters"][k] = float(v)
    for k in drop_exact:
        del d["parameters"]["exact"][k]
    rep2, problems = Report.from_dict(d)
    assert not problems, problems
    return {c.id: c.status for c in api.verify(rep2).claims if not c.id.startswith("report-")}


_MR_BREVE_SETS = (
    '[sets.X0]\ntype = "box"\nlower = [-1, -1]\nupper = [-0.9, -0.9]\n\n'
    '[sets.Xhat0]\ntype = "box"\nlower = [0.9, 0.9]\nupper = [1, 1]\n\n[method]'
)


@pytest.fixture(scope="module")
def mr_best_rate() -> Report:
    """λ omitted (best certified rate: ρ(A − LC) = 0.95 exactly), ρ = 0.955 given."""
    return _mr_design(variant(replace=[("lambda = 0.955\n", "")]))


@pytest.fixture(scope="module")
def mr_breve_rho_reported() -> Report:
    """Section 4 (X0, X̂0) with neither λ nor ρ in the spec: ρ = λ² is a report value."""
    return _mr_design(
        variant(
            add='X0 = "X0"\nXhat0 = "Xhat0"',
            replace=[
                ("lambda = 0.955\n", ""),
                ("rho = 0.955\n", ""),
                ("[method]", _MR_BREVE_SETS),
            ],
        )
    )


def test_float_only_breve_values_are_refused(mr_breve_rho_reported) -> None:
    """v̆_max / θ̆ with their exact value removed: a failed ``<key>-exact`` claim (kills
    ``params.exact(key, None)`` in ``_breve``, which dropped the v̆_max / θ̆ claims silently
    and certified the report)."""
    rep = mr_breve_rho_reported
    assert _mr_failed(rep) and all(s != ClaimStatus.FAILED for s in _mr_failed(rep).values())
    for k in ("v_max_breve", "theta_breve"):
        st = _mr_failed(rep, drop_exact=(k,))
        assert st.get(f"{k}-exact") == ClaimStatus.FAILED, st


def test_float_only_lambda_infeasible_is_refused(mr_best_rate) -> None:
    """λ_infeasible with its exact value removed: ``lambda_infeasible-exact`` fails (kills
    ``params.exact("lambda_infeasible", None)``: no claim, the report certified)."""
    st = _mr_failed(mr_best_rate, drop_exact=("lambda_infeasible",))
    assert st.get("lambda_infeasible-exact") == ClaimStatus.FAILED, st


def test_lambda_bracket_of_zero_width_is_true(mr_best_rate) -> None:
    """λ = λ_infeasible = ρ(A − LC) = 0.95: the bracket claim (0.95 infeasible, width 0 ≤
    rate_tol) is true and passes; decay-lmi fails (λ = 0.95 is not a certified rate). Kills
    ``0 <= width`` → ``0 < width`` (fails a true bracket claim)."""
    lam = fmpq(19, 20)
    st = _mr_failed(mr_best_rate, **{"lambda": lam, "lambda_infeasible": lam})
    assert st["lambda-bracket"] == ClaimStatus.CERTIFIED
    assert {k for k, s in st.items() if s == ClaimStatus.FAILED} == {"decay-lmi"}


def test_v_max_breve_bound_needs_rho_below_one(mr_breve_rho_reported) -> None:
    """A reported ρ = 3/2: v̆_max = V0 + μ|w|²/(1 − ρ) is meaningless (no contraction); the
    v̆_max claim fails however large v̆_max is (kills ``rho < 1`` → ``rho < 2``)."""
    st = _mr_failed(mr_breve_rho_reported, rho=fmpq(3, 2))
    assert st["v_max_breve-bound"] == ClaimStatus.FAILED
    assert st["iss-bound"] == ClaimStatus.FAILED


def test_nonlinear_plant_with_the_linear_observer() -> None:
    """f, h given as expressions but no F: the sampled ISS check builds the linear observer
    x̂⁺ = Ax̂ + Bu + L(y − Cx̂) from [system] and L (kills every mutant of that branch of
    ``_iss_sampled``: each made the claim crash, failing a true report)."""
    from test_constrained_nonlinear import NL

    text = (
        NL.replace('F = ["x2_hat + 0.2*(y1 - x1_hat)", "0.5*sin(x1_hat)"]\n', "L = [0.2, 0.5]\n")
        .replace("mu = 0.2", "mu = 5")
        .replace('f = ["x2", "0.5*sin(x1)"]', 'f = ["x2", "0.5*x1"]')
        .replace("A = [[0, 1], [0, 0]]", "A = [[0, 1], [0.5, 0]]")
    )
    sp = load_spec_text(text, "nl.toml")
    assert sp.options.model.F is None and sp.options.model.nonlinear
    rep = api.design(sp)
    st = {c.id: c.status for c in rep.claims}
    assert st["iss-bound"] == ClaimStatus.NUMERICAL
    assert not [c.id for c in rep.claims if c.status == ClaimStatus.FAILED]


def test_contains_q_of_an_ellipsoid_off_the_origin() -> None:
    """The vertex test against an ellipsoid not centred at 0 uses v − centre (kills
    ``v + S.center_q``, which e.g. put X0's vertices in an off-centre X̂ wrongly)."""
    from obsdesign.methods.constrained.claims import contains_q
    from obsdesign.sets import Ellipsoid

    E = np.array([[fmpq(1), fmpq(0)], [fmpq(0), fmpq(1)]], dtype=object)
    S = Ellipsoid(E, np.array([fmpq(2), fmpq(0)], dtype=object))
    assert contains_q(S, np.array([fmpq(2), fmpq(0)], dtype=object))
    assert contains_q(S, np.array([fmpq(3), fmpq(0)], dtype=object))
    assert not contains_q(S, np.array([fmpq(0), fmpq(0)], dtype=object))


@pytest.fixture(scope="module")
def mr_sec5() -> Report:
    """λ = 0.955 and ρ = 0.955 given (the Section 5 design without [simulate])."""
    return _mr_design(spec_text())


@pytest.mark.parametrize("key", ["theta", "P", "L"])
def test_float_only_required_or_copied_value_is_refused(mr_sec5, key) -> None:
    """A required parameter (θ, P) or the report's copy of the spec's L with its exact value
    removed: ``<key>-exact`` fails (kills ``params.exact(k, None)`` in ``certify``: with it, a
    float-only θ made certify return no claim at all, and a float-only L copy was never
    compared)."""
    st = _mr_failed(mr_sec5, drop_exact=(key,))
    assert st.get(f"{key}-exact") == ClaimStatus.FAILED, st


def _mr_q(rows) -> np.ndarray:
    return np.array([[fmpq(x) for x in r] for r in rows], dtype=object)


def _mr_v(xs) -> np.ndarray:
    return np.array([fmpq(x) for x in xs], dtype=object)


def test_cmin_in_xhat_box_map_keeps_each_upper_bound_on_its_axis() -> None:
    """Box map with different upper bounds per axis (x1 ≤ 1, x2 ≤ 3), ε_min = 1/100 (t =
    1/10): the outer box of C_min is [−1.1, 1.1] × [−1.1, 3.1]. X̂ = [−2, 2] × [−2, 3.2]
    contains it, X̂ = [−2, 3.2] × [−2, 2] does not (kills ``h_q[2i − 1]``, which swapped the
    upper bounds between the axes and certified the second)."""
    from obsdesign.methods.constrained.claims import cmin_in_xhat
    from obsdesign.methods.constrained.cmap import box_map
    from obsdesign.sets import Box

    cm = box_map(_mr_v([-1, -1]), _mr_v([1, 3]))
    eps = fmpq(1, 100)
    assert cmin_in_xhat(cm, eps, Box(_mr_v([-2, -2]), _mr_v([2, fmpq(16, 5)])))[0]
    assert not cmin_in_xhat(cm, eps, Box(_mr_v([-2, -2]), _mr_v([fmpq(16, 5), 2])))[0]


def test_cmin_in_xhat_refuses_an_unbounded_outer_set() -> None:
    """A polytope map {x1 ≤ 1, x2 ≤ 1} (a wedge: one vertex, unbounded): C_min is unbounded
    and lies in no bounded X̂, whatever its vertex does (kills ``not bounded and len(V) == 0``
    and ``return True`` for an unbounded outer set)."""
    from obsdesign.methods.constrained.claims import cmin_in_xhat
    from obsdesign.methods.constrained.cmap import polytope_map
    from obsdesign.sets import Box

    cm = polytope_map(_mr_q([[1, 0], [0, 1]]), _mr_v([1, 1]))
    ok, detail = cmin_in_xhat(cm, fmpq(1, 100), Box(_mr_v([-5, -5]), _mr_v([5, 5])))
    assert not ok and "unbounded" in detail


def test_cmin_in_xhat_ellipsoid_map_support_function() -> None:
    """Ellipsoid map Q = I/4, r = 10/11, ε_min = 1/100 (t = 1/10): the outer set of C_min is
    {xᵀx/4 ≤ 1}, the disc of radius 2, whose support in ±e_i is √(R·e_iᵀQ⁻¹e_i) = 2 exactly.
    X̂ = [−2, 2]² contains it (a face touching: ``>`` not ``>=``), X̂ = [−1.9, 1.9]² does not
    (``√(R/w)`` = 1/2 certified it)."""
    from obsdesign.methods.constrained.claims import cmin_in_xhat
    from obsdesign.methods.constrained.cmap import ellipsoid_map
    from obsdesign.sets import Box

    cm = ellipsoid_map(_mr_q([[fmpq(1, 4), 0], [0, fmpq(1, 4)]]), fmpq(10, 11))
    eps = fmpq(1, 100)
    assert cmin_in_xhat(cm, eps, Box(_mr_v([-2, -2]), _mr_v([2, 2])))[0]
    assert not cmin_in_xhat(cm, eps, Box(_mr_v([fmpq(-19, 10)] * 2), _mr_v([fmpq(19, 10)] * 2)))[0]


@pytest.mark.parametrize("add", ["eps_max = 140098", "gamma = 0.00002"])
def test_a_spec_fixed_eps_max_or_gamma_verifies(add) -> None:
    """ε_max or γ fixed by the spec: the design's report (its copy equal to the spec's) has no
    failed claim (kills ``c.matches(key, None, …)`` / ``(…, key_value, None, …)``, which
    failed ``<key>-matches-spec`` on every such report)."""
    rep = _mr_design(variant(add=add))
    assert not [c.id for c in api.verify(rep).claims if c.status == ClaimStatus.FAILED]


@pytest.mark.parametrize("drop", ["all", "exact"])
def test_a_missing_lambda_is_refused(mr_best_rate, drop) -> None:
    """λ omitted by the spec is a design output; a report without it (or float-only) fails
    ``lambda-present`` / ``lambda-exact`` (kills ``params.exact("lambda", None)``: the decay
    LMI and the bracket were then silently skipped and the report certified)."""
    d = mr_best_rate.to_dict()
    del d["parameters"]["exact"]["lambda"]
    if drop == "all":
        del d["parameters"]["lambda"]
    rep2, problems = Report.from_dict(d)
    assert not problems, problems
    failed = {c.id for c in api.verify(rep2).claims if c.status == ClaimStatus.FAILED}
    assert ("lambda-present" if drop == "all" else "lambda-exact") in failed, failed


def test_delta_bound_below_one_and_at_equality(mr_sec5) -> None:
    """δ-bound is true for a δ below 1 (ε_max = 0.02 given: δ = 2√ε_max ≈ 0.28; kills
    ``delta >= 1``) and for δ·δ = δ² exactly (kills ``delta * delta > dsq``)."""
    rep = api.design(load_spec_text(variant(add="eps_max = 0.02"), "t.toml"))
    st = {c.id: c.status for c in rep.claims}
    assert rep.parameters["delta"] < 1 and st["delta-bound"] == ClaimStatus.CERTIFIED
    delta = mr_sec5.parameters["delta"]
    assert _mr_failed(mr_sec5, delta_sq=delta * delta)["delta-bound"] == ClaimStatus.CERTIFIED


def test_v_min_zero_is_a_true_bound(mr_sec5) -> None:
    """v_min = 0 (V ≤ 0 means x̂ = x ∈ X ⊂ C_min): v_min-bound holds (kills ``v_min > 0``,
    which failed it); θ must then cover v_max − 0, so only theta-covers may fail."""
    st = _mr_failed(mr_sec5, v_min=fmpq(0))
    assert st["v_min-bound"] == ClaimStatus.CERTIFIED
    assert {k for k, s in st.items() if s == ClaimStatus.FAILED} <= {"theta-covers"}


# -- mutation review 2026-11-27b (constrained/claims.py): the key / id string mutants ----------
# (to append to tests/test_constrained_method.py: uses _mr_q / _mr_v of "mutation review
# 2026-11-27" above)


def test_cmin_in_xhat_near_tight_off_centre_ellipsoid() -> None:
    """Ellipsoid map Q = I, r = 10/11, ε_min = 1/100 (t = 1/10): the outer set of C_min is the
    unit disc. X̂ = {((x1 − 1/2)/s)² + (x2/2)² ≤ 1} with s = 3/2 + 10⁻¹⁴ contains it, touching
    it nearly at (−1, 0); the S-lemma multipliers τ that prove it form a window of width
    ≈ 10⁻⁷, which the bounded search finds only with its tolerance xatol = 10⁻¹²·(1 − cᵀEc)
    (kills ``options={"XXxatolXX": …}`` / ``{"XATOL": …}`` in ``ellipsoid_in_ellipsoid``:
    scipy ignores the unknown option, searches to its default xatol = 10⁻⁵, and a true
    C_min ⊂ X̂ fails). With s = 3/2 − 10⁻¹⁴ the inclusion is false and is not proved."""
    from obsdesign.methods.constrained.claims import cmin_in_xhat
    from obsdesign.methods.constrained.cmap import ellipsoid_map
    from obsdesign.sets import Ellipsoid

    cm = ellipsoid_map(_mr_q([[1, 0], [0, 1]]), fmpq(10, 11))
    eps = fmpq(1, 100)
    for s, inside in ((fmpq(3, 2) + fmpq(1, 10**14), True), (fmpq(3, 2) - fmpq(1, 10**14), False)):
        X = Ellipsoid(_mr_q([[1 / (s * s), 0], [0, fmpq(1, 4)]]), _mr_v([fmpq(1, 2), 0]))
        ok, detail = cmin_in_xhat(cm, eps, X)
        assert bool(ok) == inside, (s, detail)


def test_cmin_in_xhat_box_map_uses_the_closed_form() -> None:
    """Box map, X̂ a box: C_min ⊂ X̂ is decided in closed form over the outer box (n faces
    per side), not by enumerating its 2ⁿ vertices with cdd.gmp. Not a verdict: kills
    ``cm.kind == "XXboxXX"`` / ``"BOX"`` in ``cmin_in_xhat``, which gave the same answer by
    vertex enumeration (n = 13: 2.4 s instead of 0.5 s; exponential in n, and an exception
    where cdd.gmp is unavailable)."""
    from obsdesign.methods.constrained.claims import cmin_in_xhat
    from obsdesign.methods.constrained.cmap import box_map
    from obsdesign.sets import Box

    cm = box_map(_mr_v([-1, -1]), _mr_v([1, 3]))
    ok, detail = cmin_in_xhat(cm, fmpq(1, 100), Box(_mr_v([-2, -2]), _mr_v([2, fmpq(16, 5)])))
    assert ok and "outer box" in detail, detail


def test_rho_below_the_best_rate_squared_names_the_key() -> None:
    """λ omitted, ρ given (outsider trial, session 22): A − LC = 0.2, so any ρ needs ρ ≥ 0.04,
    but ρ = 0.03 ran on to μ of eq. (5) and ended exit 4 ("inconclusive") for a request no P
    can meet. Now exit 2 naming [method.rho] with λ_best²; ρ = 0.05 ≥ λ_best² designs."""
    text = (
        '[system]\ntime = "discrete"\nA = [[0.5]]\nC = [[1]]\n[sets.X]\ntype = "box"\n'
        'lower = [-1]\nupper = [1]\n[method]\nkey = "constrained"\nL = [0.3]\nrho = {rho}\n'
        'X = "X"\neps_min = 0.01\n[method.c]\ntype = "box"\nlower = [-1.1]\nupper = [1.1]\n'
        "[method.D]\nlower = [-0.1]\nupper = [0.1]\n"
    )
    with pytest.raises(SpecError, match=r"\[method\.rho\] expected rho >= λ_best² = 0\.04") as e:
        api.design(load_spec_text(text.format(rho="0.03"), "rho.toml"))
    assert e.value.exit_code == 2 and "spectral radius ≈ 0.2" in e.value.message
    rep = api.design(load_spec_text(text.format(rho="0.05"), "rho.toml"))
    assert rep.exit_code() == 0


def test_simulate_names_the_largest_certified_gamma_rounded_down() -> None:
    """An uncertified simulation γ (outsider trial, session 22): the text said "certified γ =
    10" for the spec's own γ = 10 (gamma_uncertified = true; the bound (24) is γ_max ≈
    0.0433), and "certified γ = 6980" for γ_max = 348983/50 = 6979.66 (rounded up: not
    certified). It now names γ_max rounded down; every γ up to the printed value is
    certified, checked exactly against the report's γ_max."""
    from obsdesign.certify.exact import Q

    base = (
        '[system]\ntime = "discrete"\nA = [[0.5]]\nC = [[1]]\n[sets.X]\ntype = "box"\n'
        'lower = [-1]\nupper = [1]\n[method]\nkey = "constrained"\nL = [0.3]\nX = "X"\n'
        'eps_min = 0.01\n{extra}[method.c]\ntype = "box"\nlower = [-1.1]\nupper = [1.1]\n'
        "[method.D]\nlower = [-0.1]\nupper = [0.1]\n[simulate]\nhorizon = 5\nx0 = [1]\n"
        "xhat0 = [1.2]\ntheta_m = 2\n"
    )
    for extra, opts, shown in (
        ("", {"gamma": "100000"}, "6979"),
        ("gamma = 7000\ngamma_uncertified = true\n", {}, "6979"),
    ):
        spec = load_spec_text(base.format(extra=extra), "g.toml")
        rep = api.design(spec)
        g_max = Q(rep.parameters["gamma_max"])
        assert g_max == fmpq(348983, 50)
        text = api.simulate(spec, rep, options=opts).info["gamma (simulation)"]
        assert text.endswith(f"certified γ ≤ {shown})"), text
        assert Q(shown) <= g_max


_DEFECTIVE = """[system]
time = "discrete"
A = [[1, 1], [0, 1]]
C = [[1, 0]]
[sets.X]
type = "box"
lower = [-1, -1]
upper = [1, 1]
[method]
key = "constrained"
L = [1, 0.25]
X = "X"
eps_min = 0.01
lambda = 0.500000000001
[method.c]
type = "box"
lower = [-1.1, -1.1]
upper = [1.1, 1.1]
[method.D]
lower = [-0.01]
upper = [0.01]
"""


def test_a_rate_just_above_a_defective_eigenvalue_certifies() -> None:
    """A − LC has the defective eigenvalue 1/2 and λ = 1/2 + 10⁻¹²: P ≻ 0 holds exactly but
    its float λ_min is ≤ 0, and the design said "no γ > 0 satisfies (24)" (exit 1,
    infeasible) although the lyapunov method certifies the same P (unusual-spec trial,
    session 24). Now γ comes from an exact lower bound of λ_min(P), and verify agrees."""
    rep = api.design(load_spec_text(_DEFECTIVE, "defective.toml"))
    assert rep.exit_code() == 0, [c.detail for c in rep.claims if not c.passed]
    assert float(rep.parameters.float("gamma")) > 0
    assert api.verify(rep).exit_code() == 0


#: the Section 5 spec with L = (−0.2, 0.85): A − LC = [[1/5, 1], [3/20, 0]], eigenvalues 1/2
#: and −3/10 (λ, ρ and the margin filled in by each test)
RHO_HALF = (
    (Path(__file__).resolve().parents[1] / "specs" / SEC5)
    .read_text()
    .split("\n[simulate]\n")[0]
    .replace("L = [-1.87, 1.874]", "L = [-0.2, 0.85]")
    .replace("lambda = 0.955", "lambda = LAM\nmargin = MARGIN")
    .replace("rho = 0.955", "rho = LAM")
)


@pytest.mark.parametrize(
    ("lam", "margin", "head"),
    [
        ("0.5", "0", "no P ≻ 0 from the Lyapunov equation gives"),
        ("0.5", "1e-9", "no P ≻ 0 gives"),
        ("0.49", "0", "no P ≻ 0 from the Lyapunov equation gives"),
    ],
)
def test_a_rate_at_or_below_the_radius_is_decided_exactly_and_said_truly(lam, margin, head):
    """A − LC = [[1/5, 1], [3/20, 0]] has the eigenvalues 1/2 and −3/10. λ = ρ = 1/2 with
    margin 0 was refused "no P ≻ 0 gives decay rate λ = 0.5", which is false there: P =
    [[17/32, 5/16], [5/16, 25/8]] meets the non-strict claim (constrained soundness trial,
    session 25); the message now says the Lyapunov equation gives none and why."""
    from obsdesign.errors import InfeasibleError

    text = RHO_HALF.replace("LAM", lam).replace("MARGIN", margin)
    with pytest.raises(InfeasibleError) as e:
        api.design(load_spec_text(text, "rho.toml"))
    assert e.value.message.startswith(head) or f": {head}" in str(e.value), str(e.value)
    assert ("non-strict" in str(e.value)) == (margin == "0")


def test_a_rate_a_hair_above_the_radius_is_no_infeasibility() -> None:
    """λ = 1/2 + 10⁻²⁰ is above ρ = 1/2: the refusal compared float(λ) with the float radius,
    which at this distance could fall either way (here the float radius came out just below
    0.5); the exact test now decides, and the rounded P's exact check settles the rest (here:
    exit 4, the rate is too close to the limit), never exit 1."""
    from obsdesign.errors import InconclusiveError, InfeasibleError

    lam = "0.50000000000000000001"
    text = RHO_HALF.replace("LAM", lam).replace("MARGIN", "0")
    try:
        rep = api.design(load_spec_text(text, "rho.toml"))
    except InfeasibleError as e:
        raise AssertionError(f"a false infeasibility verdict: {e}") from None
    except InconclusiveError:
        return
    assert rep.exit_code() in (0, 4)


def _jordan_spec(A: str, n: int) -> str:
    box = lambda b: f"lower = {[-b] * n}\nupper = {[b] * n}"  # noqa: E731
    return (
        f'[system]\ntime = "discrete"\nA = {A}\nC = [{[1] + [0] * (n - 1)}]\n'
        f'[sets.X]\ntype = "box"\n{box(1)}\n[sets.Xh]\ntype = "box"\n{box(1.5)}\n'
        f'[method]\nkey = "constrained"\nL = {[0] * n}\nX = "X"\nXhat = "Xh"\neps_min = 0.01\n'
        f'[method.c]\ntype = "box"\n{box(1.1)}\n[method.D]\nlower = [-0.1]\nupper = [0.1]\n'
    )


def test_a_schur_gain_with_a_float_radius_above_one_is_decided_exactly() -> None:
    """A − LC similar to a 4×4 Jordan block at 0.99999 is Schur, but its float spectral
    radius is 1.00017 and the design refused it, "not Schur" (exit 1), before any exact test
    (edge-shape trial, session 26; lyapunov certified λ = 0.999999 for the same A − LC). The
    float radius now only raises the question; an exact test decides both ways."""
    A = "[[0.99999, 1, 0, 0], [0, 0.99999, 1, 0], [-1, 1, -0.00001, 1], [-1, 2, -2, 1.99999]]"
    assert max(abs(np.linalg.eigvals(np.array(eval(A))))) > 1  # the float radius misleads
    rep = api.design(load_spec_text(_jordan_spec(A, 4), "jordan.toml"))
    assert rep.exit_code() == 0 and all(c.status == ClaimStatus.CERTIFIED for c in rep.claims)
    assert api.verify(rep).exit_code() == 0
    with pytest.raises(InfeasibleError, match=r"not Schur \(an eigenvalue of modulus ≥ 1, exact"):
        api.design(load_spec_text(_jordan_spec("[[0, 1], [-1, 0]]", 2), "rot.toml"))
    # the message's "≈" figure is the spectral guide's, naming its source: float eigenvalues
    # printed 1.00017 here for an exact 1.00001 (lyapunov trial, session 34)
    A = "[[1.00001, 1, 0, 0], [0, 1.00001, 1, 0], [-1, 1, 0.00001, 1], [-1, 2, -2, 2.00001]]"
    with pytest.raises(
        InfeasibleError, match=r"spectral radius ≈ 1\.00001 from roots of the exact"
    ):
        api.design(load_spec_text(_jordan_spec(A, 4), "jordan.toml"))


def test_rho_and_lambda_are_printed_exactly_in_their_statements():
    """ρ and λ appear in `iss-bound` and `decay-lmi` exactly: rounded up to 10 digits,
    ρ = 0.99999999999 read "ρ = 1, …, ρ < 1", a certified statement contradicting itself
    (rendering trial, session 27). verify recomputes the same statements."""
    from obsdesign.certify.exact import Q

    text = variant(replace=(("rho = 0.955", "rho = 0.99999999999"),))
    rep = api.design(load_spec_text(text, "rho.toml"))
    st = {c.id: c for c in rep.claims}
    iss = st["iss-bound"]
    assert iss.status == ClaimStatus.CERTIFIED
    assert "with ρ = 0.99999999999, " in iss.statement and "ρ = 1," not in iss.statement
    lam = st["decay-lmi"].statement.rsplit("with λ = ", 1)[1]
    assert Q(lam) == rep.parameters["lambda"]
    assert api.verify(rep).exit_code() == 0


USER_P_REFUTED = """[system]
time = "discrete"
A = [[0, 1], [1, 0]]
C = [[1, 0]]
[sets.X]
type = "box"
lower = [-1, -1]
upper = [1, 1]
[method]
key = "constrained"
L = [-0.9, 1.2]
P = [[6.5, 3.5], [3.5, 6.5]]
rho = 0.8
mu = 200
X = "X"
eps_min = 0.5
[method.c]
type = "box"
lower = [-1, -1]
upper = [1, 1]
[method.D]
lower = [-0.5]
upper = [0.5]
[simulate]
horizon = 20
x0 = [-1, 1]
xhat0 = [0.5, -0.5]
theta_m = [1000]
"""


def test_simulate_names_a_refuted_assumption_2_among_the_premises(tmp_path) -> None:
    """A user's P, ρ, μ whose inequality (5) the exact LDLᵀ refutes (design: iss-bound
    failed, exit 1) was simulated with "premises of Theorem 1 (25b): hold" (soundness trial,
    session 30): Assumption 2 is a premise of Theorem 1, and the line now names it. A P for
    which (5) holds (ρ = 0.81, μ = 10⁴) gives "hold"."""
    p = tmp_path / "u.toml"
    p.write_text(USER_P_REFUTED)
    assert api.design(api.load_spec(p)).exit_code() == 1
    info = api.simulate(p).info
    assert info["premises of Theorem 1 (25b)"].startswith("Assumption 2 fails: V(e⁺) ≤ ρV(e)")
    p.write_text(
        USER_P_REFUTED.replace("[[6.5, 3.5], [3.5, 6.5]]", "[[3.2, 2.8], [2.8, 4.9]]")
        .replace("rho = 0.8\n", "rho = 0.81\n")
        .replace("mu = 200", "mu = 10000")
    )
    assert api.design(api.load_spec(p)).exit_code() == 0
    assert api.simulate(p).info["premises of Theorem 1 (25b)"] == "hold"


# -- mutation review 30 (docs/mutation.md)


# --- Mutation review 30: constrained sim._assumption2_refuted (ready to append to
# tests/test_constrained_method.py)


def test_simulate_names_assumption_2_refuted_just_below_the_needed_mu(tmp_path) -> None:
    """Mutation review 30 (sim._assumption2_refuted: μ (or ρ) changed in the exact check,
    e.g. 2μ): with P = [[3.2, 2.8], [2.8, 4.9]], ρ = 0.81 the inequality (5) needs
    μ ≳ 3.93; μ = 3 is refuted by the design (exit 1) and named by simulate, μ = 4 holds."""
    p = tmp_path / "u.toml"
    base = USER_P_REFUTED.replace("[[6.5, 3.5], [3.5, 6.5]]", "[[3.2, 2.8], [2.8, 4.9]]").replace(
        "rho = 0.8\n", "rho = 0.81\n"
    )
    p.write_text(base.replace("mu = 200", "mu = 3"))
    assert api.design(api.load_spec(p)).exit_code() == 1
    got = api.simulate(p).info["premises of Theorem 1 (25b)"]
    assert got.startswith("Assumption 2 fails: V(e⁺) ≤ ρV(e) + μ|w|² (eq. (5))"), got
    p.write_text(base.replace("mu = 200", "mu = 4"))
    assert api.design(api.load_spec(p)).exit_code() == 0
    assert api.simulate(p).info["premises of Theorem 1 (25b)"] == "hold"


def test_simulate_names_a_P_below_the_margin_as_assumption_2_failing(tmp_path) -> None:
    """Mutation review 30 (sim._assumption2_refuted: the P test dropped, or made without
    [method] margin): a P positive definite but not above margin·I (the design's P-positive
    claim fails, exit 1) is named by simulate as failing eq. (4), as the design says."""
    p = tmp_path / "u.toml"
    text = USER_P_REFUTED.replace("[[6.5, 3.5], [3.5, 6.5]]", "[[3.2, 2.8], [2.8, 4.9]]")
    text = text.replace("rho = 0.8\n", "rho = 0.81\n").replace("mu = 200", "mu = 10000")
    assert "[method]\n" in text
    p.write_text(text.replace("[method]\n", "[method]\nmargin = 1000\n", 1))
    rep = api.design(api.load_spec(p))
    assert rep.exit_code() == 1 and "P-positive-definite" in {c.id for c in rep.failed}
    got = api.simulate(p).info["premises of Theorem 1 (25b)"]
    assert got.startswith("Assumption 2 fails: P is not positive definite"), got


TINY = """[system]
time = "discrete"
A = [[0.5]]
C = [[1]]
[sets.X]
type = "box"
lower = [-1e-12]
upper = [1e-12]
[sets.Xh]
type = "box"
lower = [-1.5e-12]
upper = [1.5e-12]
[method]
key = "constrained"
L = [0.9]
lambda = 0.5
X = "X"
Xhat = "Xh"
eps_min = 1e-26
[method.c]
type = "box"
lower = [-1.1e-12]
upper = [1.1e-12]
[method.D]
lower = [-1e-12]
upper = [1e-12]
[simulate]
horizon = 300
x0 = [1e-12]
xhat0 = [-1.5e-12]
theta_m = [0, 3]
[simulate.noise]
kind = "uniform"
bound = 1e-12
"""


def test_simulate_flags_hold_at_any_scale(tmp_path: Path) -> None:
    """At scale 10⁻¹² the simulate flags used absolute tolerances (10⁻⁹ for X, X̂; 10⁻¹² for
    D): "x̂_k in X̂ for all k ≥ 1: True" with x̂_1 = 1.75·10⁻¹² outside X̂ = ±1.5·10⁻¹², and
    "premises … hold" with x̂_0, x_0 outside or noise 100× outside D (soundness trial,
    session 34). The tolerance is now 10⁻⁹ of each set's own size."""
    p = tmp_path / "tiny.toml"

    def info(text: str) -> dict:
        p.write_text(text)
        return api.simulate(p).info

    got = info(TINY)
    assert got["modified θ_m=0: x̂_k in X̂ for all k ≥ 1"] is False
    assert got["modified θ_m=3: x̂_k in X̂ for all k ≥ 1"] is False
    got = info(TINY.replace("x0 = [1e-12]\nxhat0 = [-1.5e-12]", "x0 = [3e-12]\nxhat0 = [5e-12]"))
    premises = got["premises of Theorem 1 (25b)"]
    assert "the estimate starts outside X̂" in premises and "the plant leaves X at k = 0" in premises
    small_D = TINY.replace(
        "lower = [-1e-12]\nupper = [1e-12]\n[simulate]",
        "lower = [-1e-14]\nupper = [1e-14]\n[simulate]",
    )
    assert small_D != TINY
    premises = info(small_D)["premises of Theorem 1 (25b)"]
    assert premises.startswith("w_k = (d_k, v_k) leaves D at k = ") and "e-1" in premises
    # x̂_0 on X̂'s boundary, x, w inside: no premise of the run itself is flagged (only the
    # step budgets, which these θ_m are below)
    premises = info(TINY)["premises of Theorem 1 (25b)"]
    assert "X̂" not in premises and "leaves" not in premises and "all spent" in premises


def test_simulate_names_the_observer_its_metrics_and_csv_are_of() -> None:
    """The metrics table and --csv are of the first modified observer (θ_m = 10, with the
    uncertified γ = 17 on Section 5) and said only "simulation metrics" (soundness trial,
    session 34): the info and the table's title name it."""
    spec = Path(__file__).resolve().parents[1] / "specs" / SEC5
    assert api.simulate(spec).info["observer"] == "modified θ_m=10"
    r = CliRunner().invoke(app, ["simulate", str(spec)])
    assert r.exit_code == 0 and "simulation metrics (modified θ_m=10)" in r.stdout, r.stdout


def test_the_noise_premise_reads_each_coordinate_of_d_at_its_own_scale() -> None:
    """D = [−1, 1] × [−10⁻¹², 10⁻¹²]: noise 8·10⁻¹² is 8× outside the thin coordinate, and the
    widest side's tolerance (2·10⁻⁹) passed it as "premises hold" (mutation review 35, T7). A
    zero-width coordinate at 10⁸ still takes a sample one float spacing off as on it (the
    spacing allowance, T12)."""
    import types

    from obsdesign.certify.exact import qvec
    from obsdesign.methods.constrained.sim import _outside_premises
    from obsdesign.sets import Box

    K = 3
    o = types.SimpleNamespace(
        D_lower=np.array([-1.0, -1e-12]),
        D_upper=np.array([1.0, 1e-12]),
        X=Box(qvec([-10]), qvec([10])),
        model=None,
        U_lower=np.array([]),
    )
    x, u, d = np.zeros((K, 1)), np.zeros((K, 0)), np.zeros((K, 1))
    out = _outside_premises(o, x, u, d, np.full((K, 1), 8e-12))
    assert out and out[0].startswith("w_k = (d_k, v_k) leaves D at k = 0")
    assert _outside_premises(o, x, u, d, np.full((K, 1), 0.5e-12)) == []
    o.D_lower, o.D_upper = np.array([-1.0, 1e8]), np.array([1.0, 1e8])
    near = np.full((K, 1), np.nextafter(1e8, np.inf))
    assert _outside_premises(o, x, u, d, near) == []


def test_rho_below_lambda_squared_says_it_is_the_designs_rule() -> None:
    """Independent fuzz 37: ρ < λ² said "β(v, d) = ρv + μ|d|² needs ρ ≥ λ²", which is not true
    (for the design's P, (5) holds a little below λ²): it is the design's rule, and the message
    says so and how to get a smaller ρ (a smaller lambda)."""
    text = (
        '[system]\ntime = "discrete"\nA = [[0.5]]\nC = [[1]]\n[sets.X]\ntype = "box"\n'
        'lower = [-1]\nupper = [1]\n[method]\nkey = "constrained"\nL = [0.3]\nlambda = 0.9\n'
        'rho = 0.5\nX = "X"\neps_min = 0.01\n[method.c]\ntype = "box"\nlower = [-1.1]\n'
        "upper = [1.1]\n[method.D]\nlower = [-0.1]\nupper = [0.1]\n"
    )
    with pytest.raises(SpecError, match=r"\[method\.rho\] expected rho >= lambda² = 0\.81") as e:
        load_spec_text(text, "rho.toml")
    assert "needs" not in e.value.message and "give lambda <= √rho" in e.value.message


def test_counts_of_one_are_singular_in_the_messages() -> None:
    """ "1 positive numbers" and "(1 numbers)" for a 1-state plant (re-check trial, session
    41)."""
    from obsdesign.methods.constrained.options import _count

    assert _count(1) == "1 number" and _count(3) == "3 numbers"
    assert _count(1, "positive number") == "1 positive number"
    text = (
        '[system]\ntime = "discrete"\nA = [[0.5]]\nC = [[1]]\n'
        '[sets.X]\ntype = "box"\nlower = [-1]\nupper = [1]\n'
        '[method]\nkey = "constrained"\nL = [0.1]\nlambda = 0.9\nX = "X"\neps_min = 0.01\n'
        '[method.c]\ntype = "box"\nlower = [-1.1]\nupper = [1.1]\n'
        "[simulate]\nhorizon = 10\nx0 = [1]\nxhat0 = [0]\n"
    )
    with pytest.raises(SpecError, match=r"bounds of w = \(d, v\) \(1 number\)$"):
        load_spec_text(text, "sg.toml")


@pytest.mark.parametrize("key", ["rate_tol", "lambda"])
def test_a_certificate_beyond_the_float_range_names_the_keys(key: str) -> None:
    """A − LC = 0 with rate_tol = 1e-300 (or λ = 1e-300): the P of the decay LMI with the
    default margin is beyond the float range, and the design ended with the report's generic
    "integer division result too large for a float", naming no key (degenerate-sizes review,
    session 42). Exit 4 naming the key to change and margin = 0."""
    from obsdesign.errors import InconclusiveError

    text = (
        '[system]\ntime = "discrete"\nA = [[0.5]]\nC = [[1]]\n'
        '[sets.X]\ntype = "box"\nlower = [-1]\nupper = [1]\n'
        '[method]\nkey = "constrained"\nL = [0.5]\nX = "X"\n'
        f"{key} = 1e-300\neps_min = 0.01\n"
        '[method.c]\ntype = "box"\nlower = [-1.1]\nupper = [1.1]\n'
        "[method.D]\nlower = [-3]\nupper = [3]\n"
    )
    with pytest.raises(InconclusiveError) as ei:
        api.design(api.load_spec_text(text, "s.toml"))
    msg = ei.value.message
    assert "P at λ = 1e-300 has entries beyond the float range" in msg
    # not "margin = 0": with it the design reaches μ of eq. (5), whose S = λ²P − … is then
    # singular in floats (exit 4 saying so; it was exit 3; re-check review, session 42)
    assert "[method].lambda" in msg and "margin = 0" not in msg
    nil = (  # A − LC = [[0, 1], [0, 0]], nilpotent
        '[system]\ntime = "discrete"\nA = [[0, 1], [1, 0]]\nC = [[1, 0]]\n'
        '[sets.X]\ntype = "box"\nlower = [-1, -1]\nupper = [1, 1]\n'
        '[method]\nkey = "constrained"\nL = [0, 1]\nX = "X"\nmargin = 0\n'
        f"{key} = 1e-300\neps_min = 0.01\n"
        '[method.c]\ntype = "box"\nlower = [-1.1, -1.1]\nupper = [1.1, 1.1]\n'
        "[method.D]\nlower = [-3]\nupper = [3]\n"
    )
    with pytest.raises(
        InconclusiveError, match=r"S = ρP − \(A − LC\)ᵀP\(A − LC\) is singular"
    ) as e2:
        api.design(api.load_spec_text(nil, "s.toml"))
    # the key to change (the message named none and ended mid-sentence; session 43)
    assert e2.value.message.endswith(
        "a larger [method].lambda (or [method].rate_tol when λ is the best rate)"
    )
    assert ("[method].rate_tol (now 1e-300)" in msg) == (key == "rate_tol")


def test_an_inclusion_whose_float_norm_overflows_is_false_not_undecided() -> None:
    """X̂ = [−1e80, 1e80]² with the Section 5 box map and ε_max = 100: |c| ≈ 1.4·10¹⁶⁰ at X̂'s
    corners overflowed in floats and the float estimate from below dropped those points and
    said 0, so the failed inclusion read "undecided", exit 4 (float pre-screen review, session
    42). In float64 |c| = inf > ε_max as well: exit 1."""
    text = (TSPECS.parent.parent / "specs" / "constrained-redesign-sec5.toml").read_text(
        encoding="utf-8"
    )
    text = text.replace(
        "[method]\n",
        '[sets.Xh]\ntype = "box"\nlower = [-1e80, -1e80]\nupper = [1e80, 1e80]\n\n[method]\n',
        1,
    ).replace('key = "constrained"\n', 'key = "constrained"\nXhat = "Xh"\neps_max = 100\n', 1)
    rep = api.design(api.load_spec_text(text, "s.toml"))
    bad = {c.id: c.float_ok for c in rep.claims if not c.ok}
    assert rep.exit_code() == 1, bad
    assert bad.get("Xhat-in-Cmax") is False


def test_the_lambda_bracket_names_the_discrete_time_test() -> None:
    """The constrained method is discrete-time: its lambda-bracket check said "exact Routh
    test", the continuous-time test (random-plant review, session 43)."""
    from obsdesign import api

    spec = Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5.toml"
    text = spec.read_text(encoding="utf-8")
    lines = [ln for ln in text.splitlines() if not ln.startswith("lambda = ")]
    rep = api.design(api.load_spec_text("\n".join(lines) + "\n", "best.toml"))
    (claim,) = [c for c in rep.claims if c.id == "lambda-bracket"]
    assert "Schur–Cohn" in claim.check and "Routh" not in claim.check


@pytest.mark.parametrize("c", ["1e308", "-1e308"])
def test_a_closed_loop_past_the_float_range_is_decided_exactly(c: str) -> None:
    """C = [[1e308, 0]]: A − LC overflowed to inf in floats and eigvals raised LinAlgError,
    exit 3 (CLI review, session 44). The exact Schur–Cohn test decides: not Schur, exit 1."""
    text = variant(replace=[("C = [[1, 0]]", f"C = [[{c}, 0]]")])
    assert f"C = [[{c}, 0]]" in text
    with pytest.raises(InfeasibleError, match="A − LC is not Schur"):
        api.design(load_spec_text(text, "c.toml"))


def test_the_best_rate_note_names_the_discrete_time_test(specs_dir) -> None:
    """The note of a best-rate design said "(exact Routh test)", the continuous-time test,
    where its lambda-bracket claim names Schur–Cohn, the one that ran (re-check review 45)."""
    text = (specs_dir / "constrained-redesign-sec5.toml").read_text(encoding="utf-8")
    assert "lambda = 0.955\n" in text
    rep = api.design(api.load_spec_text(text.replace("lambda = 0.955\n", ""), "best.toml"))
    note = next(n for n in rep.notes if n.startswith("λ: the best certified rate"))
    assert "(exact Schur–Cohn test)" in note and "Routh" not in note, note
