"""python-control interop (obsdesign/interop.py, issue 14 item 4): StateSpace → spec →
design → observer StateSpace, whose simulated error decays at the certified rate; the
MATLAB .mat import."""

from __future__ import annotations

import json
import tomllib
from decimal import Decimal
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

import obsdesign
from obsdesign import api
from obsdesign.cli import app
from obsdesign.errors import InputError, SpecError
from obsdesign.interop import (
    observer_statespace,
    spec_from_statespace,
    spec_text_from_statespace,
)

control = pytest.importorskip("control")
ROOT = Path(__file__).resolve().parents[1]
A_D = [[0.5, 0.1], [0.30000000000000004, 0.8]]  # 0.1 + 0.2: its repr reads back bit for bit
A_C = [[0.0, 1.0], [-2.0, -0.5]]


def _plant_with_state(sys: object) -> object:
    """The plant with outputs y (named y[j]) and x (named x[i]) for interconnection."""
    n, p, m = sys.nstates, sys.noutputs, sys.ninputs
    C2 = np.vstack([sys.C, np.eye(n)])
    D2 = np.vstack([sys.D, np.zeros((n, m))])
    return control.ss(
        sys.A,
        sys.B,
        C2,
        D2,
        sys.dt,
        inputs=[f"u[{i}]" for i in range(m)],
        outputs=[f"y[{j}]" for j in range(p)] + [f"x[{i}]" for i in range(n)],
        name="plant",
    )


def _errors(sys: object, obs: object, T: np.ndarray, x0: list[float], xh0: list[float]):
    """x − x̂ along the interconnection of the plant and the observer (u(t) = sin t)."""
    n = sys.nstates
    plant = _plant_with_state(sys)
    joint = control.interconnect(
        [plant, obs],
        inplist=["u[0]"],
        outlist=[f"x[{i}]" for i in range(n)] + [f"xhat[{i}]" for i in range(n)],
    )
    U = np.sin(T).reshape(1, -1)
    r = control.input_output_response(joint, T, U, X0=[*x0, *xh0])
    out = np.asarray(r.outputs)
    return out[:n] - out[n:]


def test_toml_writes_exact_reprs():
    sys = control.ss(A_D, [[0], [1]], [[1, 0]], [[0]], 0.1)
    text = spec_text_from_statespace(sys, "lyapunov", **{"lambda": 0.9})
    d = tomllib.loads(text)
    assert d["system"]["A"] == A_D  # the same doubles, bit for bit
    assert d["system"]["sample_time"] == 0.1 and d["system"]["time"] == "discrete"
    assert "0.30000000000000004" in text
    assert d["method"] == {"key": "lyapunov", "lambda": 0.9}
    assert "D" not in d["system"]  # an all-zero D is left out
    cont = tomllib.loads(spec_text_from_statespace(control.ss(A_C, [[0], [1]], [[1, 0]], 0)))
    assert cont["system"]["time"] == "continuous" and "sample_time" not in cont["system"]
    disc = tomllib.loads(spec_text_from_statespace(control.ss(A_D, [[0], [1]], [[1, 0]], 0, True)))
    assert disc["system"]["time"] == "discrete" and "sample_time" not in disc["system"]


def test_discrete_round_trip_error_decays_at_the_certified_rate():
    sys = control.ss(A_D, [[0], [1]], [[1, 0]], [[0]], 0.1)
    sp = obsdesign.spec_from_statespace(sys, "lyapunov", **{"lambda": 0.9})
    rep = api.design(sp)
    assert rep.exit_code() == 0
    lam = float(rep.parameters.float("lambda"))
    P = np.asarray(rep.parameters.float("P"), float)
    L = np.asarray(rep.parameters.float("L"), float).reshape(2, 1)
    obs = rep.observer_statespace()
    assert isinstance(obs, control.StateSpace) and obs.dt == 0.1
    np.testing.assert_array_equal(obs.A, np.asarray(A_D) - L @ np.array([[1.0, 0.0]]))
    T = np.arange(0, 61) * 0.1
    e = _errors(sys, obs, T, [1.0, -1.0], [0.0, 0.0])
    V = np.einsum("ik,ij,jk->k", e, P, e)
    k = np.arange(len(T))
    # V(e_k) ≤ λ^{2k} V(e_0): the certified decay (float slack only)
    assert np.all(V <= lam ** (2 * k) * V[0] * (1 + 1e-9) + 1e-300)
    assert np.linalg.norm(e[:, -1]) < 1e-2 * np.linalg.norm(e[:, 0])


def test_continuous_round_trip_error_decays_at_the_certified_rate():
    sys = control.ss(A_C, [[0], [1]], [[1, 0]], [[0]])
    rep = api.design(spec_from_statespace(sys, "lyapunov"))  # alpha designed (best)
    assert rep.exit_code() == 0
    alpha = float(rep.parameters.float("alpha"))
    P = np.asarray(rep.parameters.float("P"), float)
    obs = observer_statespace(rep)
    assert isinstance(obs, control.StateSpace) and obs.dt == 0
    T = np.linspace(0, 8, 401)
    e = _errors(sys, obs, T, [1.0, 0.5], [0.0, 0.0])
    V = np.einsum("ik,ij,jk->k", e, P, e)
    # V(e(t)) ≤ e^{−2αt} V(e(0)), with the ODE solver's relative tolerance as slack
    assert np.all(V <= np.exp(-2 * alpha * T) * V[0] * (1 + 1e-4) + 1e-9 * V[0])
    assert V[-1] < np.exp(-2 * alpha * T[-1]) * V[0] * 1.01


def test_set_invariant_linear_and_piecewise_observers():
    rep = api.design(api.load_spec(ROOT / "specs" / "dorea-pimenta-7-1.toml"))
    assert rep.exit_code() == 0
    sp = api.load_spec(ROOT / "specs" / "dorea-pimenta-7-1.toml")
    A, B, C = sp.system.A.f, sp.system.B.f, sp.system.C.f
    obs = observer_statespace(rep, law="linear")
    # the spec's [method].L (reported as L_user), as simulate's law=linear runs it; the
    # design's midpoint L was exported in its place (papers review 46)
    L = np.asarray(rep.parameters.float("L_user"), float).reshape(2, 1)
    assert not np.allclose(L, np.asarray(rep.parameters.float("L"), float).reshape(2, 1))
    np.testing.assert_allclose(obs.A, A + L @ C, rtol=0, atol=1e-15)  # x̂⁺ = A x̂ − L z
    nl = observer_statespace(rep, law="interpolated")
    assert isinstance(nl, control.NonlinearIOSystem) and not isinstance(nl, control.StateSpace)
    from obsdesign.methods.setinvariant.sim import make_law

    f = make_law(sp, rep.parameters, "interpolated")
    xh, y = np.array([0.3, -0.2]), np.array([0.5])
    w = np.concatenate([np.zeros(B.shape[1]), y])
    z = y - C @ xh
    want = A @ xh - np.asarray(f(float(z[0]), 0), float)
    np.testing.assert_allclose(nl._rhs(0, xh, w), want, rtol=0, atol=1e-15)


def test_methods_without_a_linear_observer_say_so():
    rep = api.design(api.load_spec(ROOT / "specs" / "constrained-redesign-sec5.toml"))
    with pytest.raises(InputError, match="not linear"):
        observer_statespace(rep)


def test_mat_import_round_trip(tmp_path: Path):
    from scipy.io import savemat

    A = np.array(A_D)
    mat = tmp_path / "plant.mat"
    savemat(
        mat, {"Ad": A, "Bd_in": np.array([[0.0], [1.0]]), "Cm": np.array([[1.0, 0.0]]), "Ts": 0.1}
    )
    r = CliRunner().invoke(
        app, ["import", str(mat), "--A", "Ad", "--B", "Bd_in", "--C", "Cm", "--dt-var", "Ts"]
    )
    assert r.exit_code == 0, r.stderr
    d = tomllib.loads(r.stdout)
    assert d["system"]["A"] == A_D and d["system"]["sample_time"] == 0.1
    assert d["system"]["B"] == [[0], [1]] and d["method"] == {"key": "lyapunov"}
    spec = tmp_path / "spec.toml"
    spec.write_text(r.stdout.replace('key = "lyapunov"', 'key = "lyapunov"\nlambda = 0.9'))
    out = CliRunner().invoke(app, ["design", str(spec), "--format", "json"])
    assert out.exit_code == 0 and json.loads(out.stdout)["verdict"] == "ok"
    bad = CliRunner().invoke(app, ["import", str(mat), "--A", "A", "--C", "Cm"])
    assert bad.exit_code == 2 and "no variable 'A'" in bad.stderr and "Ad" in bad.stderr
    bad = CliRunner().invoke(
        app, ["import", str(mat), "--A", "Ad", "--C", "Cm", "--method", "lyapunv"]
    )
    assert bad.exit_code == 2 and "did you mean 'lyapunov'" in bad.stderr


@pytest.mark.parametrize(
    ("extra", "args", "message"),
    [
        ({"Ts": "x"}, ["--dt-var", "Ts"], "'Ts' (the sample time) is not a real numeric scalar"),
        ({"Ts": np.array([[1.0, 2.0]])}, ["--dt-var", "Ts"], "not a real numeric scalar"),
        ({"Ts": np.nan}, ["--dt-var", "Ts"], "'Ts' (the sample time) is nan; expected a finite"),
        # -1 is MATLAB's "no sample time" (session 39): -2 is refused
        ({"Ts": -2.0}, ["--dt-var", "Ts"], "(the sample time) is -2; expected a finite number"),
        ({"Ad": np.array([[np.inf, 0], [0, 1]])}, [], "'Ad' (A) has a non-finite entry"),
        ({"Ad": np.zeros((2, 2, 2))}, [], "'Ad' (A) has 3 dimensions, not 2"),
        ({"Ad": np.zeros((2, 3))}, [], "plant.mat: state-space shapes do not fit"),
        # outsider trial, session 26: a 0×0 plant and a subnormal entry were printed into a
        # spec the loader refuses; --dt beside --dt-var was ignored
        ({"Ad": np.zeros((0, 0)), "Cm": np.zeros((0, 0))}, [], "A has shape (0, 0): a plant"),
        ({"Ad": np.array([[5e-324, 0], [0, 1]])}, [], "the entry 5e-324, a nonzero number below"),
        ({"Ts": 0.1}, ["--dt-var", "Ts", "--dt", "0.2"], "by --dt or by --dt-var, not both"),
    ],
)
def test_mat_import_bad_variables_are_exit_2_naming_file_and_variable(
    tmp_path: Path, extra: dict, args: list[str], message: str
) -> None:
    """Found by the CLI fuzzer: a string --dt-var was an internal failure (exit 3, "could not
    convert string to float"); a vector or NaN sample time, a 3-D or non-finite matrix were
    taken or failed without naming the file."""
    from scipy.io import savemat

    mat = tmp_path / "plant.mat"
    savemat(mat, {"Ad": np.array(A_D), "Cm": np.array([[1.0, 0.0]]), **extra})
    r = CliRunner().invoke(app, ["import", str(mat), "--A", "Ad", "--C", "Cm", *args])
    assert r.exit_code == 2, r.stderr
    assert message in r.stderr and str(mat) in r.stderr and len(r.stderr.splitlines()) == 1


def test_stubborn_luenberger_part():
    text = spec_text_from_statespace(
        control.ss([[0.7, 0.7], [-0.7, 0.7]], [[0], [1]], [[1, 1]], 0, 1), "stubborn"
    )
    rep = api.design(api.load_spec_text(text, "<stubborn>"))
    assert rep.exit_code() == 0
    K = np.asarray(rep.parameters.float("K"), float).reshape(2, 1)
    obs = rep.observer_statespace()
    assert isinstance(obs, control.StateSpace) and obs.dt == 1
    A = np.array([[0.7, 0.7], [-0.7, 0.7]])
    np.testing.assert_allclose(obs.A, A - K @ np.array([[1.0, 1.0]]), rtol=0, atol=1e-15)
    np.testing.assert_allclose(obs.B[:, 1:], K, rtol=0, atol=0)
    assert max(abs(np.linalg.eigvals(obs.A))) < 1  # the Luenberger part alone is stable


def test_a_feedthrough_with_a_zero_B_is_kept() -> None:
    """(A, B, C, D) = (0.5, 0, 1, 2) (outsider trial, session 22): the spec had `inputs = 1`
    and no D, so the designed observer's u-column was 0 instead of −L D. D is written
    whenever it is not all zero, and the observer's u-column is −L D."""
    from obsdesign import interop

    plant = (np.array([[0.5]]), np.array([[0.0]]), np.array([[1.0]]), np.array([[2.0]]), 0.1)
    text = interop.spec_text_from_statespace(plant, "lyapunov")
    assert "inputs = 1" in text and "D = [[2" in text
    rep = api.design(interop.spec_from_statespace(plant, "lyapunov"))
    L = rep.parameters.float("L").reshape(1, 1)
    np.testing.assert_allclose(rep.observer_statespace().B[:, 0], -2.0 * L[:, 0])


@settings(max_examples=200, deadline=None)
@given(st.text())
def test_a_title_is_always_valid_toml(title: str) -> None:
    """Any title (a .mat file's name with ESC or CR in it wrote a raw control character, and
    the spec `import` printed was not TOML: outsider trial, session 22) reads back as itself,
    a lone surrogate as U+FFFD."""
    from obsdesign import interop

    plant = (np.array([[0.5]]), np.zeros((1, 0)), np.array([[1.0]]), np.zeros((1, 0)), 0.1)
    text = interop.spec_text_from_statespace(plant, "lyapunov", title=title)
    want = "".join("\ufffd" if 0xD800 <= ord(c) <= 0xDFFF else c for c in title)
    if title:
        assert tomllib.loads(text)["title"] == want
    else:
        assert "title" not in tomllib.loads(text)


def test_a_transfer_function_or_a_short_tuple_is_input_error() -> None:
    """``spec_from_statespace(control.tf(...))`` raised AttributeError (outsider trial,
    session 22): anything but a state-space system or a 4/5-tuple is InputError (exit 2)
    saying what to pass."""
    from obsdesign import interop

    with pytest.raises(InputError, match=r"TransferFunction: convert it first, e\.g\. control\.ss"):
        interop.spec_from_statespace(control.tf([1], [1, 2]), "lyapunov")
    with pytest.raises(InputError, match="got 3 items"):
        interop.spec_from_statespace((np.eye(1), np.eye(1), np.eye(1)), "lyapunov")
    sys_ = control.ss(control.tf([1], [1, 2]))
    assert interop.spec_from_statespace(sys_, "lyapunov").system.n == 1


@pytest.mark.parametrize(
    ("B", "D", "Bd", "bad"),
    [
        ([[1, 2, 3], [4, 5, 6]], None, None, "B has shape (2, 3)"),  # 3 states
        (np.eye(3)[:, :1], [[1, 2, 3, 4]], None, "D has shape (1, 4)"),
        (None, None, [[1, 2, 3], [4, 5, 6]], "Bd has shape (2, 3)"),
        ([1, 2, 3], [0.5], None, None),  # a vector: one column
        ([[1, 2, 3]], [[0.5]], [[1, 0, 0]], None),  # one row of n: one column
    ],
)
def test_wrongly_shaped_B_D_Bd_are_refused(B, D, Bd, bad) -> None:
    """Independent soundness trial (session 23): a 2×3 B for 3 states was reshaped row-major to
    [[1, 2], [3, 4], [5, 6]] (neither B nor Bᵀ) and the design certified that plant; D and Bd
    alike. Now B and Bd need n rows (a vector is one column) and D must be p×m."""
    A = np.diag([0.5, 0.2, 0.1])
    C = np.array([[1.0, 1.0, 1.0]])
    m = 0 if B is None else np.atleast_2d(np.asarray(B)).size // 3
    plant = (A, np.zeros((3, 0)) if B is None else B, C, np.zeros((1, m)) if D is None else D)
    if bad is None:
        text = spec_text_from_statespace(plant, "lyapunov", Bd=Bd)
        sp = api.load_spec_text(text, "<s>")
        assert np.asarray(sp.system.B.f).tolist() == [[1.0], [2.0], [3.0]]
        return
    with pytest.raises(InputError, match=bad.replace("(", r"\(").replace(")", r"\)")):
        spec_text_from_statespace(plant, "lyapunov", Bd=Bd)


def test_integers_are_written_exactly_and_complex_is_refused(tmp_path: Path) -> None:
    """An int64 entry 2⁵³ + 1 of a .mat file was written as 9007199254740992.0 (a conversion to
    float) and certified (soundness trial, session 23): integers are written exactly. A
    complex entry was cast to its real part through the tuple path: refused."""
    from scipy.io import savemat

    mat = tmp_path / "big.mat"
    savemat(mat, {"A": np.array([[0.5]]), "C": np.array([[2**53 + 1]], dtype=np.int64)})
    r = CliRunner().invoke(app, ["import", str(mat), "--A", "A", "--C", "C"])
    assert r.exit_code == 0, r.stderr
    assert tomllib.loads(r.stdout)["system"]["C"] == [[2**53 + 1]]
    with pytest.raises(InputError, match="complex"):
        spec_text_from_statespace((np.array([[0.5 + 1j]]), [], [[1.0]], []), "lyapunov")


def test_mat_import_D_without_B_gives_a_spec_that_designs(tmp_path: Path) -> None:
    """`obsdesign import --D` without `--B` wrote a spec that design refused ("[system.D]
    expected shape 1×0"): the inputs enter y only, so B is n×m zeros."""
    from scipy.io import savemat

    mat = tmp_path / "d.mat"
    savemat(mat, {"Ad": np.array(A_D), "Cm": np.array([[1.0, 0.0]]), "Dm": np.array([[2.0]])})
    r = CliRunner().invoke(app, ["import", str(mat), "--A", "Ad", "--C", "Cm", "--D", "Dm"])
    assert r.exit_code == 0, r.stderr
    rep = api.design(api.load_spec_text(r.stdout, "d.toml"))
    assert rep.exit_code() == 0 and "D = [[2]]" in r.stdout


def test_import_checks_declared_shapes_before_loading(tmp_path) -> None:
    """A 70 kB .mat holding a 3000×3000 A was imported into a 9-million-value spec (exit 0,
    8.8 s) that every command refused, and a 7.5 MB file of compressed zeros inflated to
    11 GB (hostile-input trial, session 24). The declared shapes are checked first
    (scipy's whosmat), and only the named variables are loaded: a large unrelated variable
    costs nothing."""
    import scipy.io as sio

    from obsdesign.errors import InputError
    from obsdesign.interop import spec_text_from_mat

    big = tmp_path / "big.mat"
    sio.savemat(big, {"A": np.zeros((3000, 3000)), "C": np.ones((1, 3000))}, do_compression=True)
    with pytest.raises(InputError, match="variable 'A' \\(A\\) is 3000×3000, above 100 states"):
        spec_text_from_mat(big, {"A": "A", "C": "C"})
    ok = tmp_path / "ok.mat"
    sio.savemat(
        ok,
        {
            "A": np.array([[0.0, 1], [1, 0]]),
            "C": np.array([[1.0, 0]]),
            "junk": np.zeros((999, 999)),
        },
        do_compression=True,
    )
    assert "A = [[0, 1], [1, 0]]" in spec_text_from_mat(ok, {"A": "A", "C": "C"})
    with pytest.raises(InputError, match="variables: A, C, junk"):
        spec_text_from_mat(ok, {"A": "X", "C": "C"})


def test_exact_inputs_are_written_exactly_or_refused() -> None:
    """Decimal, Fraction and long double entries were rounded to doubles: the certificate
    was about another matrix (sweep, import and check trial, session 28). A Decimal keeps its
    digits, a Fraction its finite decimal (1/3 is refused), a long double its shortest repr
    at its own precision."""
    from decimal import Decimal
    from fractions import Fraction

    from obsdesign.api import load_spec_text
    from obsdesign.errors import InputError
    from obsdesign.interop import spec_text_from_statespace

    z, c = np.zeros((2, 0)), np.array([[1.0, 0.0]])
    A = np.array(
        [[Decimal("0.1000000000000000000001"), Fraction(-1, 8)], [Decimal("1E-7"), 2]],
        dtype=object,
    )
    t = spec_text_from_statespace((A, z, c, np.zeros((1, 0)), True))
    assert "A = [[0.1000000000000000000001, -0.125], [1e-7, 2]]" in t
    got = load_spec_text(t, "x.toml").system.A.q
    assert [[Fraction(int(x.p), int(x.q)) for x in row] for row in got] == [
        [Fraction("0.1000000000000000000001"), Fraction(-1, 8)],
        [Fraction(1, 10**7), 2],
    ]
    L = np.array([[np.longdouble(1) / 3, np.longdouble(0.5)], [0, 1]], dtype=np.longdouble)
    t = spec_text_from_statespace((L, z, c, np.zeros((1, 0)), True))
    row = next(ln for ln in t.splitlines() if ln.startswith("A ="))
    if np.finfo(np.longdouble).nmant > 52:  # x86: 80-bit long double
        assert row == "A = [[0.33333333333333333334, 0.5], [0, 1]]"
    with pytest.raises(InputError, match=r"A\[0, 0\]: the exact number 1/3 has no finite"):
        spec_text_from_statespace(
            (np.array([[Fraction(1, 3)]], dtype=object), np.zeros((1, 0)), [[1.0]], [], True)
        )


def test_lists_of_tables_and_missing_values() -> None:
    """A list of tables (``windows = [{...}]``) or a None in a list raised RecursionError
    (session 28): tables are inline tables, None is refused naming the key."""
    from obsdesign.api import load_spec_text
    from obsdesign.errors import InputError
    from obsdesign.interop import spec_text_from_statespace

    plant = (np.array([[0.5]]), np.zeros((1, 0)), np.array([[1.0]]), np.zeros((1, 0)), True)
    sim = {
        "horizon": 10,
        "x0": [1],
        "xhat0": [0],
        "noise": {"kind": "windows", "windows": [{"start": 1, "stop": 2, "value": [3]}]},
    }
    t = spec_text_from_statespace(plant, "lyapunov", simulate=sim)
    assert "windows = [{start = 1, stop = 2, value = [3]}]" in t
    load_spec_text(t, "x.toml")
    with pytest.raises(InputError, match=r"\[method\] L: a missing value \(None\)"):
        spec_text_from_statespace(plant, "lyapunov", L=[None, 1])


@pytest.mark.parametrize(
    ("extra", "args", "message", "names_file"),
    [
        ({"C0": np.zeros((0, 2))}, ["--C", "C0"], "'C0' (C) is 0×2: a plant needs", True),
        ({"ts": 5e-324}, ["--dt-var", "ts"], "'ts' (the sample time) is 5e-324, a nonzero", True),
        ({}, ["--dt", "1e-320"], "--dt is 1e-320, a nonzero number below", False),
        ({}, ["--dt", "inf"], "--dt 'inf': expected a finite number", False),
        # the text as typed: 1e999 said "--dt inf" (CLI review, session 42), and "expected a
        # finite number" of a finite text past the float range (CLI review 45)
        ({}, ["--dt", "1e999"], "--dt '1e999': beyond the float range", False),
        # an exponent past Decimal's own range said "expected a number" (re-check 45)
        ({}, ["--dt", "1e100000000000000000000"], "beyond the float range", False),
        ({}, ["--dt", "1e-100000000000000000000"], "below the float range", False),
        # Arabic-Indic digits: Decimal read them, --limit refuses them (CLI review 45)
        ({}, ["--dt", "٠٫١"], "expected a number of seconds", False),
        ({}, ["--dt", "-2"], "--dt '-2': expected a finite number >= 0", False),
        # −1e-400 rounds to −0.0: it passed as continuous time (session 43)
        ({}, ["--dt", "-1e-400"], "--dt '-1e-400': expected a finite number >= 0", False),
        # below the float range: read as 0.0, continuous time, silently (session 38)
        ({}, ["--dt", "1e-400"], "--dt '1e-400': a nonzero number below the float range", False),
        ({}, ["--dt", "abc"], "--dt 'abc': expected a number of seconds", False),
    ],
)
def test_mat_import_refuses_what_the_loader_would_refuse(
    tmp_path: Path, extra: dict, args: list[str], message: str, names_file: bool
) -> None:
    """import printed specs the loader refuses (C = [], sample_time = 5e-324) with exit 0,
    and --dt inf was an error that did not name --dt (sweep, import and check trial,
    session 28)."""
    from scipy.io import savemat

    mat = tmp_path / "plant.mat"
    savemat(mat, {"Ad": np.array(A_D), "Cm": np.array([[1.0, 0.0]]), **extra})
    r = CliRunner().invoke(app, ["import", str(mat), "--A", "Ad", "--C", "Cm", *args])
    assert r.exit_code == 2 and len(r.stderr.splitlines()) == 1, r.stderr
    assert message in r.stderr and (str(mat) in r.stderr) == names_file, r.stderr


def test_mat_import_of_an_empty_Bd_has_no_disturbance(tmp_path: Path) -> None:
    """A Bd with no columns was written "Bd = [[], []]", which the loader refuses."""
    from scipy.io import savemat

    mat = tmp_path / "plant.mat"
    savemat(mat, {"Ad": np.array(A_D), "Cm": np.array([[1.0, 0.0]]), "E": np.zeros((2, 0))})
    r = CliRunner().invoke(app, ["import", str(mat), "--A", "Ad", "--C", "Cm", "--Bd", "E"])
    assert r.exit_code == 0, r.stderr
    assert "Bd" not in r.stdout
    api.load_spec_text(r.stdout, "x.toml")


def test_mat_import_checks_its_spec_with_the_loader(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Whatever spec text import makes, the loader accepts, or import is exit 2 with the
    loader's reason."""
    from scipy.io import savemat

    from obsdesign import interop

    mat = tmp_path / "plant.mat"
    savemat(mat, {"Ad": np.array(A_D), "Cm": np.array([[1.0, 0.0]])})
    monkeypatch.setattr(
        interop, "spec_text_from_statespace", lambda *a, **k: "[system]\nA = [[1]]\n"
    )
    r = CliRunner().invoke(app, ["import", str(mat), "--A", "Ad", "--C", "Cm"])
    assert r.exit_code == 2 and "the imported spec would be refused" in r.stderr, r.stderr
    assert r.stdout == ""


def test_observer_statespace_checks_the_report(tmp_path: Path) -> None:
    """A report with L edited to [100, 3] (float and exact alike), which verify rejects,
    gave an unstable observer with no word (sweep, import and check trial, session 28).
    verify=True recomputes the claims; a float/exact mismatch or an edited embedded spec is
    always refused; a stored verdict other than ok warns."""
    import json
    import warnings

    from obsdesign.errors import InputError
    from obsdesign.interop import observer_statespace

    spec = Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5-lyapunov.toml"
    rep = tmp_path / "r.json"
    assert CliRunner().invoke(app, ["design", str(spec), "-q", "-o", str(rep)]).exit_code == 0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        observer_statespace(rep, verify=True)  # the genuine report: no word
    d = json.loads(rep.read_text())

    def edited(name: str, change) -> Path:
        e = json.loads(json.dumps(d))
        change(e)
        out = tmp_path / name
        out.write_text(json.dumps(e))
        return out

    def set_L(e: dict) -> None:
        e["parameters"]["L"] = [[100.0], [3.0]]
        e["parameters"]["exact"]["L"] = [["100"], ["3"]]

    consistent = edited("a.json", set_L)
    with pytest.raises(InputError, match="verify gives 'failed'"):
        observer_statespace(consistent, verify=True)
    mismatch = edited("b.json", lambda e: e["parameters"]["L"][0].__setitem__(0, 100.0))
    with pytest.raises(InputError, match="float value differs from its exact value"):
        observer_statespace(mismatch)
    respec = edited("c.json", lambda e: e.__setitem__("spec", e["spec"] + "\n"))
    with pytest.raises(InputError, match="does not match its spec_sha256"):
        observer_statespace(respec)
    failed = edited("d.json", lambda e: e["claims"][0].__setitem__("status", "failed"))
    with pytest.warns(UserWarning, match="verdict 'failed'"):
        observer_statespace(failed)


def test_a_key_that_is_not_bare_is_quoted() -> None:
    """Mutation review 28: obsdesign.interop.x__key__mutmut_4 (every key bare: 'a b = 1' is not TOML) and _12
    (``_tstr(None)``: TypeError)."""
    import tomllib

    from obsdesign.interop import _key, _value

    assert _key("start") == "start"
    assert _key("a b") == '"a b"'
    text = "w = " + _value([{"a b": 1, "c.d": 2}])
    assert tomllib.loads(text) == {"w": [{"a b": 1, "c.d": 2}]}


def test_a_zero_dimensional_array_is_its_item_and_an_object_is_refused() -> None:
    """Mutation review 28: obsdesign.interop.x__value__mutmut_20 (``item = None``), _24 (``_value(None)``): a 0-d
    array (np.array(1.5)) refused as "None"; _21 (``item is not v``): a 0-d array refused,
    and an arbitrary object recursed (RecursionError) instead of InputError."""
    from obsdesign.interop import _value

    assert _value(np.array(1.5)) == "1.5"
    assert _value(np.array(3)) == "3"
    with pytest.raises(InputError, match="cannot write a value of type object into a spec"):
        _value(object())


def test_booleans_are_written_as_toml_booleans() -> None:
    """Mutation review 28: obsdesign.interop.x__num__mutmut_1 .. _6 (pre-existing line of ``_num``: true/false
    swapped, or written "XXtrueXX" / "TRUE")."""
    from obsdesign.interop import _value

    assert _value(True) == "true" and _value(False) == "false"
    assert _value(np.bool_(True)) == "true" and _value(np.bool_(False)) == "false"


@pytest.mark.parametrize(
    "x",
    [
        Fraction(3, 10),
        Fraction(-7, 8),
        Fraction(1, 2**20),
        Fraction(1, 5**20),
        Fraction(1, 10**30),
        Fraction(1, 5**30),
        Fraction(-7, 2**70 * 5**3),
    ],
    ids=["3/10", "-7/8", "2^-20", "5^-20", "10^-30", "5^-30", "-7/(2^70 5^3)"],
)
def test_a_fraction_with_a_finite_decimal_is_written_exactly(x: Fraction) -> None:
    """Mutation review 28: obsdesign.interop.x__exact__mutmut_11 (``d / 2``: a float, refused 1/10^30), _12
    (``d // 3``: timeout), _13 (``twos - 1``: too few digits, 2^-20 rounded), _15 (``d / 5
    == 0``: 3/10 refused), _16 (``d % 6``), _19 (``d, fives = None``), _20 (``d / 5``: 5^-30
    refused), _21 (``d // 6``: timeout), _22 (``fives - 1``: 5^-20 rounded). The text is the
    fraction exactly (every Fraction test had a power-of-two denominator)."""
    from obsdesign.interop import _num

    text = _num(x)
    assert Fraction(text) == x, text


def test_exact_entries_outside_the_float_range_or_not_numbers_are_refused() -> None:
    """Mutation review 28: obsdesign.interop.x__real__mutmut_48 (``not isfinite(f) and ...``: a Decimal above
    the float range, or a nonzero one that is 0.0 as a double, passed; the spec loader
    refuses both), _35 (``isinstance(x, bool) and ...``: a bool beside a Decimal taken as
    1, text crashed with ValueError), _26 (``dtype == object or any(...)``: an object array
    of floats skipped the subnormal check)."""
    from obsdesign.interop import _real

    for big in (Decimal("1e400"), Decimal("-1e-400")):
        with pytest.raises(InputError, match="outside the float range"):
            _real(np.array([[big, 1]], dtype=object), "A")
    with pytest.raises(InputError, match="which is not a number"):
        _real(np.array([[Decimal("0.5"), "x"]], dtype=object), "A")
    with pytest.raises(InputError, match=r"A\[0, 1\] is a boolean, not a number"):
        _real(np.array([[Decimal("0.5"), True]], dtype=object), "A")
    with pytest.raises(InputError, match="subnormal|float range"):
        _real(np.array([[5e-324, 1.0]], dtype=object), "A")


def test_import_dt_zero_is_continuous_and_the_smallest_normal_dt_is_accepted(
    tmp_path: Path,
) -> None:
    """Mutation review 28: obsdesign.interop.x_spec_text_from_mat__mutmut_139 (``--dt`` check ``dt > 0``: --dt 0
    refused) and _174 (``0 <= dt``: dt 0, given or read from the file, refused as
    subnormal); _175 (``dt <= tiny``: the smallest normal double refused)."""
    from scipy.io import savemat

    from obsdesign.interop import spec_text_from_mat

    mat = tmp_path / "p.mat"
    savemat(
        mat,
        {
            "A": np.array([[0.0, 1.0], [-1.0, -1.0]]),
            "C": np.array([[1.0, 0.0]]),
            "T0": np.array([[0.0]]),
        },
    )
    names = {"A": "A", "C": "C"}
    for text in (
        spec_text_from_mat(mat, names, dt=0.0),
        spec_text_from_mat(mat, names, dt_name="T0"),
    ):
        assert "sample_time" not in text and "discrete = true" not in text, text
    tiny = float(np.finfo(float).tiny)
    assert "sample_time" in spec_text_from_mat(mat, names, dt=tiny)


def test_other_exact_rationals_are_written_exactly() -> None:
    """sympy.Rational, sympy.Integer, sympy.Matrix and flint.fmpq entries were rounded to
    doubles, while Fraction(1, 3) was refused (re-check trial, session 28): any exact
    rational is written exactly, or refused when it has no finite decimal."""
    import sympy
    from flint import fmpq

    from obsdesign.interop import _value

    big = 2**60 + 1
    A = sympy.Matrix([[sympy.Rational(3, 10), sympy.Integer(big)], [fmpq(-1, 8), 0]])
    t = spec_text_from_statespace((A, np.zeros((2, 0)), [[1.0, 0.0]], np.zeros((1, 0)), True))
    assert f"A = [[0.3, {big}], [-0.125, 0]]" in t, t
    with pytest.raises(InputError, match="1/3 has no finite decimal"):
        spec_text_from_statespace(
            (sympy.Matrix([[sympy.Rational(1, 3)]]), np.zeros((1, 0)), [[1.0]], [], True)
        )
    assert _value(fmpq(3, 8)) == "0.375" and _value(sympy.Rational(-1, 4)) == "-0.25"
    with pytest.raises(InputError, match="no finite decimal"):
        _value([fmpq(1, 3)])


@pytest.mark.parametrize(
    ("spec", "match"),
    [
        ("astolfi-stubborn-duffing.toml", "given by expressions"),
        ("hernandez-garcia-example.toml", "search-space.*not offered"),
    ],
)
def test_observer_statespace_refuses_a_plant_without_matrices(spec: str, match: str) -> None:
    """A stubborn high-gain design (plant given by f and h) and a search-space design raised
    AttributeError "'NoneType' object has no attribute 'f'" (outsider trial, session 29): a
    one-line InputError says why there is no python-control system."""
    from obsdesign import api
    from obsdesign.errors import InputError

    rep = api.design(Path(__file__).resolve().parents[1] / "specs" / spec)
    with pytest.raises(InputError, match=match):
        rep.observer_statespace()


@pytest.mark.parametrize("name", ["Ts", "dt", "T_s", "SampleTime"])
def test_import_without_a_time_choice_refuses_a_file_holding_a_sample_time(
    tmp_path: Path, name: str
) -> None:
    """A discrete plant exported with its Ts became a continuous-time spec without a word
    (outsider trial, session 29): with neither --dt nor --dt-var, a scalar named like a
    sample time asks for the choice (exit 2); --dt-var or --dt 0 decide; a file without
    one is continuous time as before."""
    from scipy.io import savemat

    from obsdesign.errors import InputError
    from obsdesign.interop import spec_text_from_mat

    mat = tmp_path / "p.mat"
    plant = {"A": np.array([[0.7, 0.7], [-0.7, 0.7]]), "C": np.array([[1.0, 1.0]])}
    savemat(mat, {**plant, name: np.array([[0.1]])})
    names = {"A": "A", "C": "C"}
    with pytest.raises(InputError, match=f"holds '{name}'.*--dt-var {name}.*--dt 0"):
        spec_text_from_mat(mat, names)
    assert 'time = "discrete"' in spec_text_from_mat(mat, names, dt_name=name)
    assert 'time = "continuous"' in spec_text_from_mat(mat, names, dt=0.0)
    savemat(mat, plant)
    assert 'time = "continuous"' in spec_text_from_mat(mat, names)


@pytest.mark.parametrize(("method", "key"), [("set-invariant", "omega"), ("constrained", "L")])
def test_mat_import_for_a_method_with_required_keys_says_where_to_start(
    tmp_path: Path, method: str, key: str
) -> None:
    """import writes [method] key only, so for a method whose [method] table has required
    keys it could never print a spec, while --help said to add the options to the printed
    table (soundness trial, session 30): exit 2 naming the missing key and `obsdesign init`."""
    from scipy.io import savemat

    mat = tmp_path / "plant.mat"
    savemat(mat, {"A": np.array(A_D), "C": np.array([[1.0, 0.0]])})
    r = CliRunner().invoke(app, ["import", str(mat), "--dt", "0.1", "--method", method])
    assert r.exit_code == 2 and r.stdout == ""
    assert f"--method {method} needs [method.{key}]" in r.stderr, r.stderr
    assert f"obsdesign init {method}" in r.stderr


def test_a_complex_value_is_refused_not_a_recursion() -> None:
    """A complex λ or an entry of L (also numpy's complex128) went through np.asarray as a
    0-d array whose item is a new complex, again and again: RecursionError (API trial,
    session 33). It is bad input naming the type."""
    from obsdesign.interop import _value

    for v in (0.955 + 0j, np.complex128(0.955), [complex(-1.87), 1.874]):
        with pytest.raises(InputError, match="cannot write a value of type complex"):
            _value(v)
    assert _value([0.5, 1]) == "[0.5, 1]"


def test_observer_statespace_refuses_a_gain_of_another_shape(tmp_path: Path) -> None:
    """A report whose L is transposed (2×3 for a 3×2 gain, float and exact alike) was
    reshaped row-major into another gain and returned without a word, while
    ``simulate --report`` refuses it (lyapunov trial, session 34)."""
    from obsdesign.interop import observer_statespace

    spec = tmp_path / "s.toml"
    spec.write_text(
        '[system]\ntime = "discrete"\nA = [[0.5, 0.1, 0], [0, 0.6, 0.2], [0.1, 0, 0.7]]\n'
        'C = [[1, 0, 0], [0, 1, 0]]\n[method]\nkey = "lyapunov"\n'
        "L = [[0.1, 0.2], [0.3, 0.4], [0.5, 0.6]]\n"
    )
    rep = tmp_path / "r.json"
    assert CliRunner().invoke(app, ["design", str(spec), "-q", "-o", str(rep)]).exit_code == 0
    obs = observer_statespace(rep)
    np.testing.assert_array_equal(obs.B[:, -2:], [[0.1, 0.2], [0.3, 0.4], [0.5, 0.6]])
    d = json.loads(rep.read_text())
    for part in (d["parameters"], d["parameters"]["exact"]):
        part["L"] = [list(col) for col in zip(*part["L"], strict=True)]
    bad = tmp_path / "t.json"
    bad.write_text(json.dumps(d))
    with pytest.raises(InputError, match=r"t\.json: parameters\.L has shape 2×3, expected 3×2"):
        observer_statespace(bad)


@pytest.mark.parametrize(
    ("A", "message"),
    [
        ([[0, 1], [1]], r"^A is not a matrix of numbers: its rows are not all of one length$"),
        ([[{}, 1], [1, 0]], r"^A\[0, 0\] = \{\}, which is not a number$"),
        ([[None, 1], [1, 0]], r"^A\[0, 0\] = None, which is not a number$"),
        ([["abc", 1], [1, 0]], r"^A has the entry 'abc', which is not a number$"),
        ([["0.1", "1"], ["1", "0"]], r"^A has the entry '0\.1', which is not a number$"),
        ([[10**400, 1.5], [1, 0]], r"^A\[0, 0\] = 1000.*: outside the float range"),
        (np.array([[10**400, 1.5], [1, 0]], dtype=object), r"^A\[0, 0\] = 1000.*: outside the"),
    ],
)
def test_statespace_matrices_that_are_not_numbers_are_input_errors(A, message) -> None:
    """Ragged rows, a dict, a word and a huge integer beside floats raised bare ValueError /
    TypeError / OverflowError, None read as "nan" and numeric text was taken as numbers
    (lyapunov trial, session 34): each is an InputError naming the matrix and the entry."""
    with pytest.raises(InputError, match=message):
        spec_text_from_statespace((A, [[0], [1]], [[1, 0]], [[0]], 1))


def test_a_large_integer_beside_floats_is_written_exactly() -> None:
    """np.asarray of [[2⁶⁰ + 1, 0.5], …] is a float array: the integer was rounded to 2⁶⁰."""
    text = spec_text_from_statespace(
        ([[2**60 + 1, 0.5], [0, 0.25]], [[0], [1]], [[1, 0]], [[0]], 1)
    )
    assert tomllib.loads(text)["system"]["A"][0] == [2**60 + 1, 0.5]


# -- mutation review 34 (session 33's checks) ----------------------------------------
def test_a_numpy_complex_is_named_by_its_own_type() -> None:
    """O01 (no isinstance(item, complex)): np.complex128's item is a Python complex, which
    the mutant still refuses one recursion later as "complex": only the type named differs."""
    from obsdesign.interop import _value

    with pytest.raises(InputError, match="of type complex128 "):
        _value(np.complex128(0.5))


def test_bytes_are_refused_not_a_recursion() -> None:
    """Kills O02 (no `type(item) is type(v)`): np.asarray(b"ab").item() is a new bytes object
    each time, never `v` itself: without the same-type test _value recursed until
    RecursionError. Bad input naming the type."""
    from obsdesign.interop import _value

    for v in (b"ab", np.bytes_(b"ab")):
        with pytest.raises(InputError, match="of type bytes"):
            _value(v)


def test_a_fraction_beyond_the_digit_limit_is_an_input_error() -> None:
    """A Fraction whose numerator has more than 4300 digits raised a bare ValueError (Python's
    int-to-text limit) from spec_from_statespace and a sweep dict grid (re-check trial,
    session 34): the digit limit names it first."""
    from obsdesign import sweep as sw

    big = Fraction(10**5000 + 1, 10**5000)
    with pytest.raises(InputError, match=r"A\[0, 0\]: the exact number's numerator or denom"):
        spec_text_from_statespace(([[big]], [[0]], [[1]], [[0]], 1))
    with pytest.raises(InputError, match="sweep: method.lambda: the exact number's numerator"):
        sw.parse_grid({"method.lambda": [big]})
    with pytest.raises(InputError, match=r"at least 500[01] digits"):
        spec_text_from_statespace(([[Fraction(1, 3 * 10**5000)]], [[0]], [[1]], [[0]], 1))


@pytest.mark.parametrize(
    "M",
    [
        [[1, True]],
        [[0.5, True]],
        [[0.5, np.bool_(True)]],
        [[Fraction(1, 2), True]],
        np.array([[1.0, 0.0], [0.0, 1.0]]) > 0.5,
        np.array([[1, False]], dtype=object),
        [[0.5, np.array(True)]],
    ],
    ids=[
        "int-list",
        "float-list",
        "numpy-bool-in-list",
        "fraction-list",
        "bool-array",
        "object",
        "0-d-array",
    ],
)
def test_a_boolean_entry_is_refused_wherever_it_sits(M: object) -> None:
    """Re-check 34 §9: booleans were taken as 1 / 0 in a plain list or beside a float and
    refused beside a Fraction; a spec refuses a boolean where a number belongs, and so does
    every matrix the interop layer reads."""
    from obsdesign.interop import _real

    with pytest.raises(InputError, match=r"A\[0, \d\] is a boolean, not a number"):
        _real(M, "A")


@pytest.mark.parametrize(
    "L",
    [
        [[True], [0.5]],
        [[np.True_], [0.5]],
        [[np.array(True)], [0.5]],
        np.array([[True], [0.5]], dtype=object),
        ([1.0], [False]),
    ],
    ids=["bool", "numpy-bool", "0-d-array", "object-array", "tuple"],
)
def test_a_boolean_in_a_method_option_is_not_written_as_a_number(L: object) -> None:
    """Re-check 35 §2: the boolean refusal covered A, B, C, D only; ``L=[[True], [0.5]]`` was
    written as L = [[1], [0.5]] and certified. It is written as ``true`` now, and the spec
    refuses it where a number belongs; a gain of plain numbers still loads."""
    from obsdesign.interop import spec_from_statespace, spec_text_from_statespace

    sys = ([[0.5, 0], [0, 0.2]], [[0], [0]], [[1, 0]], [[0]], 1)
    text = spec_text_from_statespace(sys, "lyapunov", L=L)
    assert "true" in text or "false" in text
    with pytest.raises(SpecError, match=r"\[method.L\] expected a number, got a boolean"):
        spec_from_statespace(sys, "lyapunov", L=L)
    assert spec_from_statespace(sys, "lyapunov", L=[[1], [0.5]]) is not None


def test_observer_statespace_refuses_a_stubborn_gain_of_another_shape(tmp_path: Path) -> None:
    """The stubborn twin of the lyapunov test above: a transposed K (2×3 for a 3×2 gain) was
    accepted as another gain when its shape check was weakened (mutation review 35, N12)."""
    from obsdesign.interop import observer_statespace

    spec = tmp_path / "s.toml"
    spec.write_text(
        '[system]\ntime = "continuous"\nA = [[0, 1, 0], [-1, 0, 0], [0, 0, -1]]\n'
        'C = [[1, 0, 0], [0, 0, 1]]\n[method]\nkey = "stubborn"\n'
    )
    rep = tmp_path / "r.json"
    assert CliRunner().invoke(app, ["design", str(spec), "-q", "-o", str(rep)]).exit_code == 0
    d = json.loads(rep.read_text())
    K = np.array(d["parameters"]["K"], dtype=float)
    assert K.shape == (3, 2)
    np.testing.assert_array_equal(observer_statespace(rep).B[:, -2:], K)
    for part in (d["parameters"], d["parameters"]["exact"]):
        part["K"] = [list(col) for col in zip(*part["K"], strict=True)]
    bad = tmp_path / "t.json"
    bad.write_text(json.dumps(d))
    with pytest.raises(InputError, match=r"t\.json: parameters\.K has shape 2×3, expected 3×2"):
        observer_statespace(bad)


def test_an_integer_just_above_2_53_beside_a_float_stays_exact() -> None:
    """2⁵³ + 1 has no double; beside a float it was rounded to 2⁵³ (the ``_big_int`` bound at
    2⁵⁴ passed every test: mutation review 35, N8). 2⁵³ itself is a double and may go float."""
    from obsdesign.interop import _real

    out = _real([[0.5, 2**53 + 1]], "A")
    assert out.dtype == object and int(out[0, 1]) == 2**53 + 1
    assert float(_real([[0.5, 2**53]], "A")[0, 1]) == 2.0**53


def test_an_object_array_is_written_item_by_item() -> None:
    """Mutation review 36, interop._value: a numpy object array (as pandas hands over a mixed
    column) is written item by item like a list, so a boolean in it stays `true`; a 0-d object
    array is its one item, not iterated (a TypeError; the branch's `v.ndim > 0`)."""
    from obsdesign import interop

    assert interop._value(np.array([True, 0.5], dtype=object)) == "[true, 0.5]"
    assert interop._value(np.array([[True], [0.5]], dtype=object)) == "[[true], [0.5]]"
    assert interop._value(np.array(0.5, dtype=object)) == "0.5"


@pytest.mark.parametrize("kind", ["cell", "struct"])
def test_mat_import_refuses_a_cell_or_struct_before_loading_it(
    tmp_path: Path, kind: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A 1×1 cell or struct passed the declared-shape check and ``loadmat`` inflated what it
    holds (1.1 MB to 1.4 GB; hostile-input trial, session 38): refused from ``whosmat``'s class,
    exit 2 naming file, variable and class, and ``loadmat`` is never called."""
    import scipy.io
    from scipy.io import savemat

    inner = np.array(A_D)
    wrapped = np.array([[inner]], dtype=object) if kind == "cell" else {"m": inner}
    mat = tmp_path / "plant.mat"
    savemat(mat, {"Ad": wrapped, "Cm": np.array([[1.0, 0.0]])})

    def never(*a: object, **k: object) -> None:
        raise AssertionError("loadmat called")

    monkeypatch.setattr(scipy.io, "loadmat", never)
    r = CliRunner().invoke(app, ["import", str(mat), "--A", "Ad", "--C", "Cm"])
    assert r.exit_code == 2, r.stderr
    assert f"variable 'Ad' (A) is a MATLAB {kind}, not a numeric matrix" in r.stderr
    assert str(mat) in r.stderr and len(r.stderr.splitlines()) == 1


def test_mat_import_refuses_a_variable_name_given_twice(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A MAT-5 file can hold one name twice; the shape check saw the last copy (1×1) while
    loadmat inflated every one: 498 KB to 1.7 GB (re-check trial, session 38). Refused from
    whosmat before loading, exit 2 naming the variable."""
    import scipy.io
    from scipy.io import savemat

    big, small = tmp_path / "big.mat", tmp_path / "small.mat"
    savemat(big, {"Ad": np.zeros((30, 30)), "Cm": np.array([[1.0] * 30])})
    savemat(small, {"Ad": np.array(A_D), "Cm": np.array([[1.0, 0.0]])})
    mat = tmp_path / "dup.mat"
    mat.write_bytes(big.read_bytes() + small.read_bytes()[128:])  # the second without header
    assert [n for n, _, _ in scipy.io.whosmat(str(mat))].count("Ad") == 2

    def never(*a: object, **k: object) -> None:
        raise AssertionError("loadmat called")

    monkeypatch.setattr(scipy.io, "loadmat", never)
    r = CliRunner().invoke(app, ["import", str(mat), "--A", "Ad", "--C", "Cm"])
    assert r.exit_code == 2 and "variable 'Ad' appears more than once in the file" in r.stderr
    # any name, not only the requested ones: Ts twice was read by its last copy (re-check)
    ts = tmp_path / "ts.mat"
    savemat(big, {"Ad": np.array(A_D), "Cm": np.array([[1.0, 0.0]]), "Ts": np.eye(2)})
    savemat(small, {"Ts": np.array([[0.1]])})
    ts.write_bytes(big.read_bytes() + small.read_bytes()[128:])
    r = CliRunner().invoke(app, ["import", str(ts), "--A", "Ad", "--C", "Cm"])
    assert r.exit_code == 2 and "variable 'Ts' appears more than once in the file" in r.stderr


def test_an_observer_with_no_float_realization_is_not_offered() -> None:
    """The 5-state plant with ρ(A − LC) certified at 0.647 for the exact 64-bit gain: A − LC
    formed in doubles has ρ ≈ 3.5 (even the exact A − LC rounded once has 3.6), and
    observer_statespace handed over that unstable system with no word, verify=True included
    (interop trial, session 39). Refused now; the 8-state ill-conditioned plant's doubles
    stay stable but slower than the certified λ: a warning."""
    from obsdesign.errors import InconclusiveError

    data = Path(__file__).parent / "data"
    rep = api.design(api.load_spec(data / "lyapunov-rho-6000-5state.toml"))
    assert rep.exit_code() == 0
    with pytest.raises(InconclusiveError, match="not Schur"):
        rep.observer_statespace()
    # a report whose L was replaced by an unstable one, read without verify: the refusal
    # said "the certificate holds for the exact gain", which no certificate backs (tamper
    # review 45); it says what verify is for instead
    from obsdesign.report.model import Report

    shipped = api.design(api.load_spec(ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml"))
    d = shipped.to_dict()
    d["parameters"]["L"] = [1.0, 5.0]
    d["parameters"]["exact"]["L"] = ["1", "5"]
    tampered, _ = Report.from_dict(d)
    # ... and that gain is itself unstable, exactly: not the doubles' fault (exit 4 said
    # they lost a certificate; tamper review 46) — bad input, its claims cannot hold
    with pytest.raises(InputError, match="exact gain is not Schur") as ei:
        tampered.observer_statespace()
    assert "holds for the exact gain" not in str(ei.value) and ei.value.exit_code == 2
    assert "the report's claims cannot hold for it" in str(ei.value)
    res = api.simulate(ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml", tampered)
    assert any("in doubles and for the exact gain alike" in w for w in res.info["warnings"])
    # a stable gain slower than the report's λ = 0.955 (ρ = 0.96): a warning naming the gain
    d["parameters"]["L"] = [-1.46, 1.48]
    d["parameters"]["exact"]["L"] = ["-73/50", "37/25"]
    slower, _ = Report.from_dict(d)
    with pytest.warns(UserWarning, match="exact gain does not keep the certified rate 0.955"):
        slower.observer_statespace()
    rep8 = api.design(api.load_spec(data / "lyapunov-ill-conditioned-8state.toml"))
    assert rep8.exit_code() == 0
    with pytest.warns(UserWarning, match="does not keep the certified rate"):
        ss = rep8.observer_statespace()
    assert max(abs(np.linalg.eigvals(ss.A))) < 1


def test_the_float_realization_of_a_shipped_observer_keeps_its_rate() -> None:
    """The shipped lyapunov spec: no warning, the doubles keep the certified λ."""
    import warnings

    rep = api.design(api.load_spec(ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ss = rep.observer_statespace()
    assert max(abs(np.linalg.eigvals(ss.A))) < float(rep.parameters["lambda"])


def test_a_stubborn_high_gain_plant_given_by_A_and_psi_is_not_offered() -> None:
    """mode = "high-gain" with the plant written as A + psi passed the f / h test and
    returned a linear observer with the nominal K, while the certified observer injects
    k_i·ℓ^i and runs ψ(x̂) (interop trial, session 39)."""
    text = (
        '[system]\ntime = "continuous"\nstates = ["x1", "x2"]\nA = [[0, 1], [0, 0]]\n'
        'psi = ["0", "-0.3*x2 + x1 - x1**3 + 0.5*cos(1.2*t)"]\nC = [[1, 0]]\n'
        '[method]\nkey = "stubborn"\nmode = "high-gain"\nK = [2, 1]\nlipschitz = 16\n'
        "lambda = 1\nepsilon = 1\nstate_bound = [2, 2]\n"
    )
    rep = api.design(api.load_spec_text(text, "hg.toml"))
    with pytest.raises(InputError, match="not a linear state-space system"):
        rep.observer_statespace()


def test_mat_import_takes_a_sparse_matrix_and_a_complex_one_with_zero_imaginary_part(
    tmp_path: Path,
) -> None:
    """The docs accept sparse matrices, but loadmat's scipy.sparse value became a 0-d object
    array, refused as "not a real numeric matrix"; a complex matrix with zero imaginary part
    had the same message (interop trial, session 39). Both give the dense real matrix; a
    nonzero imaginary part is named."""
    import scipy.sparse
    from scipy.io import savemat

    A = np.array(A_D)
    for name, value in (
        ("sparse", scipy.sparse.csc_matrix(A)),
        ("complex", A.astype(complex)),
    ):
        mat = tmp_path / f"{name}.mat"
        savemat(mat, {"Ad": value, "Cm": np.array([[1.0, 0.0]])})
        r = CliRunner().invoke(app, ["import", str(mat), "--A", "Ad", "--C", "Cm", "--dt", "1"])
        assert r.exit_code == 0, r.stderr
        got = tomllib.loads(r.stdout)["system"]["A"]
        np.testing.assert_array_equal(np.array(got, float), A)
    # the sample time alike: a sparse or complex (zero imaginary part) Ts
    for ts in (scipy.sparse.csc_matrix([[0.5]]), np.array([[0.5 + 0j]])):
        mat = tmp_path / "ts.mat"
        savemat(mat, {"Ad": A, "Cm": np.array([[1.0, 0.0]]), "Ts": ts})
        r = CliRunner().invoke(
            app, ["import", str(mat), "--A", "Ad", "--C", "Cm", "--dt-var", "Ts"]
        )
        assert r.exit_code == 0, r.stderr
        assert tomllib.loads(r.stdout)["system"]["sample_time"] == 0.5
    mat = tmp_path / "imag.mat"
    savemat(mat, {"Ad": A + 1j, "Cm": np.array([[1.0, 0.0]])})
    r = CliRunner().invoke(app, ["import", str(mat), "--A", "Ad", "--C", "Cm", "--dt", "1"])
    assert r.exit_code == 2 and "complex, with a nonzero imaginary part" in r.stderr


@pytest.mark.parametrize("how", ["var", "option"])
def test_mat_import_reads_matlabs_ts_minus_one_as_discrete_time_without_a_sample_time(
    tmp_path: Path, how: str
) -> None:
    """MATLAB writes Ts = -1 for a discrete-time system whose sample time is not given: it was
    refused, "expected a finite number >= 0" (interop trial, session 39). It is discrete time
    with no sample_time; -1.00000000000000001 (a float -1 that is not -1) is refused."""
    from scipy.io import savemat

    mat = tmp_path / "plant.mat"
    savemat(mat, {"Ad": np.array(A_D), "Cm": np.array([[1.0, 0.0]]), "Ts": -1.0})
    args = ["--dt-var", "Ts"] if how == "var" else ["--dt", "-1"]
    r = CliRunner().invoke(app, ["import", str(mat), "--A", "Ad", "--C", "Cm", *args])
    assert r.exit_code == 0, r.stderr
    system = tomllib.loads(r.stdout)["system"]
    assert system["time"] == "discrete" and "sample_time" not in system
    if how == "option":
        bad = ["--dt", "-1.00000000000000001"]
        r = CliRunner().invoke(app, ["import", str(mat), "--A", "Ad", "--C", "Cm", *bad])
        assert r.exit_code == 2 and "exactly -1" in r.stderr


@pytest.mark.parametrize(
    ("dt", "match"),
    [
        (Fraction(1, 10**400), "positive but below the float range"),
        (Decimal("1e-400"), "positive but below the float range"),
        (Decimal("-1e-400"), "finite positive number"),
        (Fraction(-1, 10**400), "finite positive number"),
        (float("inf"), "beyond the float range"),
        (Fraction(10**400), "beyond the float range"),
        (float("nan"), "finite positive number"),
        (Decimal("NaN"), "finite positive number"),
    ],
)
def test_a_dt_is_signed_by_its_exact_value(dt: object, match: str) -> None:
    """dt = 1/10⁴⁰⁰ read as 0.0 and wrote a continuous-time spec; −1/10⁴⁰⁰ as −0.0 passed
    (API review, session 44): the sign is the exact value's, and a dt of no float is
    refused; Fraction(0) and Decimal('0') are continuous time, 1/3 discrete."""
    from obsdesign.errors import InputError
    from obsdesign.interop import spec_text_from_statespace

    A, B, C, D = [[-0.5, 1], [0, -0.5]], [[0], [0]], [[1, 0]], [[0]]
    with pytest.raises(InputError, match=match):
        spec_text_from_statespace((A, B, C, D, dt), "lyapunov")
    for zero in (Fraction(0), Decimal("0"), Decimal("-0")):
        text = spec_text_from_statespace((A, B, C, D, zero), "lyapunov")
        assert 'time = "continuous"' in text
    text = spec_text_from_statespace((A, B, C, D, Fraction(1, 3)), "lyapunov")
    assert 'time = "discrete"' in text and "sample_time = 0.3333333333333333" in text


def test_import_of_a_fifo_names_a_matlab_file(tmp_path: Path) -> None:
    """``import ff.mat`` (a FIFO) said "refusing to read a MATLAB from it" (CLI review,
    session 44): "a MATLAB file"."""
    import os

    fifo = tmp_path / "ff.mat"
    os.mkfifo(fifo)
    r = CliRunner().invoke(app, ["import", str(fifo), "--A", "A", "--C", "C"])
    assert r.exit_code == 2
    assert "is not a regular file (refusing to read a MATLAB file from it)" in r.output


def test_an_exact_dt_is_written_as_given(tmp_path: Path) -> None:
    """``import --dt 0.1000000000000000000001`` wrote ``sample_time = 0.1``, the nearest
    double (re-check review, session 44): an exact dt (the --dt text, a Decimal, a Fraction
    with a decimal form) is written as it is, and the spec reads it back exactly; a float,
    and a Fraction with no decimal form, are written as their double."""
    from scipy.io import savemat

    from obsdesign import api
    from obsdesign.interop import spec_text_from_statespace

    A, B, C, D = [[0.5, 1], [0, 0.8]], [[0], [0]], [[1, 0]], [[0]]
    for dt, want in (
        (Decimal("0.1000000000000000000001"), "0.1000000000000000000001"),
        (Fraction(1, 8), "0.125"),
        (Decimal("1E+5"), "100000"),
        (0.1, "0.1"),
        (Fraction(1, 3), "0.3333333333333333"),
        # the exact value of 0.1's double, given exactly: written in full (it was "0.1",
        # read back as 1/10; re-check review 45)
        (Fraction(0.1), str(Decimal(0.1))),
    ):
        text = spec_text_from_statespace((A, B, C, D, dt), "lyapunov")
        assert f"sample_time = {want}\n" in text, text
        st = api.load_spec_text(text, "s.toml").system.sample_time
        assert st is not None and Fraction(str(st.q)) == Fraction(want)
    mat = tmp_path / "p.mat"
    savemat(mat, {"A": np.array(A, dtype=float), "C": np.array(C, dtype=float)})
    r = CliRunner().invoke(app, ["import", str(mat), "--dt", "0.1000000000000000000001"])
    assert r.exit_code == 0 and "sample_time = 0.1000000000000000000001\n" in r.stdout, r.output
    r = CliRunner().invoke(app, ["import", str(mat), "--dt", "1e-310"])
    assert r.exit_code == 2 and "--dt is 1e-310, a nonzero number below" in r.stderr, r.output
    # past the float range it said "expected a finite number" (CLI review 45)
    r = CliRunner().invoke(app, ["import", str(mat), "--dt", "1e400"])
    assert r.exit_code == 2 and "--dt '1e400': beyond the float range" in r.stderr, r.output


def test_table_names_are_quoted_keys() -> None:
    """A set named "X.hat" was written [sets.X.hat] (a nested table), a [simulate] sub-table
    "my noise" made invalid TOML, and a name holding "]\\n[simulate]..." injected tables
    (API review 45): each name is one quoted key; the text is valid TOML with exactly the
    tables given."""
    from obsdesign.interop import spec_text_from_statespace

    A, B, C, D = [[0.5, 1], [0, 0.5]], [[0], [0]], [[1, 0]], [[0]]
    box = {"type": "box", "lower": [-1, -1], "upper": [1, 1]}
    evil = "X]\n[simulate]\nhorizon = 7\n[sets.X"
    text = spec_text_from_statespace(
        (A, B, C, D, True),
        sets={"X.hat": box, evil: box},
        simulate={"horizon": 5, "x0": [0, 0], "xhat0": [0, 0], "my noise": {"kind": "zero"}},
    )
    doc = tomllib.loads(text)
    assert set(doc["sets"]) == {"X.hat", evil}
    assert doc["simulate"]["horizon"] == 5 and "my noise" in doc["simulate"]


def test_bad_arguments_of_the_interop_functions_are_bad_input() -> None:
    """Values nested thousands deep (RecursionError), states=5 (TypeError), an integer past
    Python's 4,300-digit text limit (ValueError), observer_statespace(None) (TypeError) were
    bare exceptions, and a law given with a lyapunov report was dropped without a word (CLI
    review 46). Each is an InputError now."""
    ss = ([[0, 1], [1, 0]], [[0], [1]], [[1, 0]], [[0]], 1)
    deep: dict = {}
    cur = deep
    for _ in range(3000):
        cur["a"] = {}
        cur = cur["a"]
    deep_list: list = []
    cur_l = deep_list
    for _ in range(3000):
        cur_l.append([])
        cur_l = cur_l[0]
    cases = (
        (lambda: spec_text_from_statespace(ss, sets={"X": deep}), "sets: nested more than"),
        (lambda: spec_text_from_statespace(ss, simulate=deep), "simulate: nested more than"),
        (lambda: spec_text_from_statespace(ss, L=deep_list), "L: nested more than"),
        (lambda: spec_text_from_statespace(ss, states=5), "states: expected a list"),
        (lambda: spec_text_from_statespace(ss, states="x1"), "states: expected a list"),
        (lambda: spec_text_from_statespace(ss, simulate=5), "simulate: expected a mapping"),
        (lambda: spec_text_from_statespace(ss, horizon=10**5000), "about 5000 digits"),
        (lambda: observer_statespace(None), "expected a Report or the path of one"),
    )
    for call, said in cases:
        with pytest.raises(InputError, match=said):
            call()
    # any integer the reader takes is written: a seed of any size, an exact entry past 2^63
    # (refused for a while by session 46's check; re-check review 46)
    text = spec_text_from_statespace(ss, L=[2**70, 0], simulate={"seed": 2**80, "horizon": 5})
    assert f"L = [{2**70}, 0]" in text and f"seed = {2**80}" in text
    # states as any sequence of names: a numpy array or a tuple (re-check review 46)
    for names in (np.array(["p", "v"]), ("p", "v")):
        assert 'states = ["p", "v"]' in spec_text_from_statespace(ss, states=names)
    rep = api.design(api.load_spec(ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml"))
    with pytest.raises(InputError, match="law 'online-lp': the lyapunov observer is linear"):
        observer_statespace(rep, law="online-lp")
    assert observer_statespace(rep, law="linear").A.shape == (2, 2)


def test_a_set_invariant_observer_with_lambda_1_is_exported() -> None:
    """λ = 1 certifies an invariant polytope, ρ(A + LC) ≤ 1: the rotation below with L = 0 is
    certified and verifies, and observer_statespace refused it as "the report's claims
    cannot hold" (the export was held to strict stability; re-check review 46)."""
    text = """
[system]
time = "discrete"
A = [[0, -1], [1, 0]]
C = [[1, 0]]
[sets.omega]
type = "symmetric-polytope"
Q = [[1, 0], [0, 1]]
[method]
key = "set-invariant"
omega = "omega"
eta_bar = 0
lambda = 1
algorithm = "symmetric"
L = [0, 0]
"""
    rep = api.design(api.load_spec_text(text, "rot.toml"))
    assert rep.exit_code() == 0 and api.verify(rep).exit_code() == 0
    obs = observer_statespace(rep, law="linear")
    np.testing.assert_array_equal(obs.A, [[0.0, -1.0], [1.0, 0.0]])
    # ... but not a gain edited to an unstable one: with λ = 1 no check ran, and it was
    # exported without a word (re-check review 46)
    from obsdesign.report.model import Report

    d = rep.to_dict()
    d["spec"] = d["spec"].replace("L = [0, 0]", "L = [5, 5]")
    import hashlib

    d["spec_sha256"] = hashlib.sha256(d["spec"].encode()).hexdigest()
    bad, _ = Report.from_dict(d)
    assert api.verify(bad).exit_code() == 1
    with pytest.raises(InputError, match="eigenvalue outside the unit disk"):
        observer_statespace(bad, law="linear")


def test_report_objects_are_read_as_verify_reads_them(tmp_path: Path) -> None:
    """A loaded report whose float L was edited in the file (the exact L untouched): verify
    of the object fails it, while observer_statespace(verify=True) and simulate of the same
    object ran — both re-read the object without the parameters as read (API review 46).
    And an object with exact values past max_digits (a set-invariant Q entry 1e-300) was
    refused by observer_statespace only, verify and simulate taking it."""
    import warnings

    from obsdesign.report.model import Report

    spec = ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml"
    good = tmp_path / "good.json"
    api.design(spec, out=good)
    d = json.loads(good.read_text(encoding="utf-8"))
    d["parameters"]["L"] = [[5.0], [5.0]]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(d), encoding="utf-8")
    rep, problems = Report.load(bad)
    assert problems and api.verify(rep).exit_code() == 1
    with pytest.raises(InputError, match="float value differs from its exact value"):
        observer_statespace(rep, verify=True)
    with pytest.raises(InputError, match="float value differs from its exact value"):
        api.simulate(spec, rep)
    text = (ROOT / "specs" / "dorea-pimenta-7-2.toml").read_text(encoding="utf-8")
    long = text.replace("[0.2681, 0.7595, -0.0851]", "[1e-300, 0.7595, -0.0851]")
    assert long != text
    r = api.design(api.load_spec_text(long, "q.toml"))
    assert r.exit_code() == 0 and api.verify(r).exit_code() == 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert observer_statespace(r, law="interpolated") is not None
