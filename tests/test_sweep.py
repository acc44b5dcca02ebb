"""Sweeps (issue 13), in-process: grid parsing with exact known answers, the spec-text edit
(only the swept key changes), one row per point whatever happens in it, the worst row's exit
code, the table formats, the CLI's refusals before any work. The Dask runs are in
tests/test_distributed.py."""

from __future__ import annotations

import csv
import json
import math
import tomllib
from pathlib import Path

import pytest
from typer.testing import CliRunner

from obsdesign import sweep as sw
from obsdesign.cli import app
from obsdesign.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml"
runner = CliRunner()


# -- grid ----------------------------------------------------------------------------------
def test_linear_range_is_exact_decimals():
    a = sw.parse_axis("method.lambda=0.90:0.99:10")
    assert a.key == "method.lambda"
    assert a.values == tuple(
        f"0.{k}" for k in ("9", "91", "92", "93", "94", "95", "96", "97", "98", "99")
    )


def test_integer_ends_give_integers_and_thirds_are_rounded_to_15_digits():
    assert sw.parse_axis("simulate.horizon=100:300:3").values == ("100", "200", "300")
    assert sw.parse_axis("k=0:1:4").values == ("0", "0.333333333333333", "0.666666666666667", "1")
    assert sw.parse_axis("k=0.0:1:3").values == ("0.0", "0.5", "1.0")
    assert sw.parse_axis("k=2.5:2.50:1").values == ("2.5",)  # one value: the ends agree


def test_log_range_hits_the_decades_exactly():
    v = sw.parse_axis("simulate.noise.bound=1e-3:1:7:log").values
    assert v == ("0.001", "0.00316227766016838", "0.01", "0.0316227766016838", "0.1",
                 "0.316227766016838", "1.0")  # fmt: skip


def test_lists_and_single_values():
    assert sw.parse_axis("method.solver=[clarabel, scs]").values == ('"clarabel"', '"scs"')
    assert sw.parse_axis("method.L=[[-1.87, 1.874], [-1.8, 1.9]]").values == (
        "[-1.87, 1.874]",
        "[-1.8, 1.9]",
    )
    assert sw.parse_axis("method.iss_gain=false").values == ("false",)
    assert sw.parse_axis('x=[1, 2.50, "a,b"]').values == ("1", "2.50", '"a,b"')


@pytest.mark.parametrize(
    "text, where",
    [
        ("method.lambda", "KEY=VALUES"),
        ("method..lambda=1", "not a dotted spec key"),
        ("x=1:2:0", "at least 1"),
        # b was dropped without a word (CLI hostile-input trial, session 34)
        ("x=2.5:7:1", "2.5:7:1 has one value but two different ends"),
        ("x=1:10:1:log", "one value but two different ends"),
        ("x=1:2:1000001", "above the limit"),
        ("x=0:1:3:log", "positive ends"),
        ("x=[1, 2", "end with ']'"),
        ("x=[]", "empty"),
        ("x=[1,,2]", "empty item"),
        ("x=1e400:1:2", "exponent"),
        ("x=a b", "not a TOML value"),
        # a range's N that is not whole, or TOML's own integer forms, said "is not a TOML
        # value" (batch trial, session 39)
        ("x=0.5:0.7:2.0", "is not a range START:STOP:N"),
        ("x=1_0:2_0:2", "is not a range START:STOP:N"),
        ("x=0x10:0x20:2", "N a whole number of values"),
    ],
)
def test_bad_axes_are_bad_input(text: str, where: str):
    with pytest.raises(InputError, match=where):
        sw.parse_axis(text)


def test_grid_is_the_product_last_axis_fastest_and_limited():
    axes = sw.parse_grid(["a.x=[1, 2]", "a.y=[3, 4, 5]"])
    pts = sw.grid_points(axes)
    assert pts == [{"a.x": x, "a.y": y} for x in "12" for y in "345"]
    with pytest.raises(InputError, match="given twice"):
        sw.grid_points(sw.parse_grid(["a.x=1", "a.x=2"]))
    with pytest.raises(InputError, match="limit"):
        sw.grid_points(sw.parse_grid(["a.x=0:1:1000", "a.y=0:1:1000"]))
    assert [a.values for a in sw.parse_grid({"a.x": [0.1, 2], "a.y": "1:2:2", "a.z": 3})] == [
        ("0.1", "2"),
        ("1", "2"),
        ("3",),
    ]


def test_a_dict_grid_takes_numpy_values_and_exact_rationals_as_numbers() -> None:
    """A numpy array was written as one string point ('[0.96 0.97]'), numpy scalars other
    than float64 as strings, and Fraction(29, 30) was rounded to 28 digits silently (API
    trial, session 33). An array is its list of points; every value is written as
    :mod:`obsdesign.interop` writes a spec's; a rational without a finite decimal is refused
    naming the key."""
    from decimal import Decimal
    from fractions import Fraction

    import numpy as np

    axes = sw.parse_grid(
        {
            "a.x": np.linspace(0.96, 0.97, 2),
            "a.y": [np.float32(0.5), np.int64(3), np.float16(0.25)],
            "a.z": [np.array([-1.87, 1.874])],
            "a.w": np.array([[1, 2], [3, 4]]),
            "a.q": [Fraction(1, 4), Decimal("0.125"), True],
        }
    )
    assert [a.values for a in axes] == [
        ("0.96", "0.97"),
        ("0.5", "3", "0.25"),
        ("[-1.87, 1.874]",),
        ("[1, 2]", "[3, 4]"),
        ("0.25", "0.125", "true"),
    ]
    with pytest.raises(InputError, match=r"sweep: a\.q: the exact number 29/30 has no finite"):
        sw.parse_grid({"a.q": [Fraction(29, 30)]})
    with pytest.raises(InputError, match=r"sweep: a\.q: cannot write the non-finite number"):
        sw.parse_grid({"a.q": [np.float32("nan")]})


# -- editing the spec text -----------------------------------------------------------------
def _changed(old: str, new: str) -> dict:
    a, b = tomllib.loads(old), tomllib.loads(new)
    return {k: (a.get(k), b.get(k)) for k in set(a) | set(b) if a.get(k) != b.get(k)}


def test_set_key_replaces_only_that_line_and_keeps_its_comment():
    text = '[method]\nkey = "lyapunov"\nlambda = 0.955  # the paper\nrate_tol = 1e-4\n'
    new = sw.set_key(text, "method.lambda", "0.97")
    assert new == '[method]\nkey = "lyapunov"\nlambda = 0.97  # the paper\nrate_tol = 1e-4\n'


def test_set_key_adds_a_missing_key_to_its_table_and_replaces_multiline_values():
    text = '[system]\nA = [[0, 1],\n     [1, 0]]  \n\n[simulate]\nhorizon = 3\n\n[simulate.noise]\nkind = "none"\n'
    new = sw.set_key(text, "system.A", "[[0, 2], [1, 0]]")
    assert tomllib.loads(new)["system"]["A"] == [[0, 2], [1, 0]]
    new = sw.set_key(text, "simulate.noise.bound", "0.5")
    assert tomllib.loads(new)["simulate"]["noise"] == {"kind": "none", "bound": 0.5}
    new = sw.set_key(text, "simulate.dt", "0.01")
    assert tomllib.loads(new)["simulate"] == {"horizon": 3, "dt": 0.01, "noise": {"kind": "none"}}
    new = sw.set_key(text, "method.lambda", "0.9")  # no [method]: a new dotted root key
    assert tomllib.loads(new)["method"] == {"lambda": 0.9}


def test_set_key_refuses_what_it_cannot_write_exactly():
    text = '[simulate]\nnoise = { kind = "none" }\n'
    with pytest.raises(InputError, match="inline table"):
        sw.set_key(text, "simulate.noise.bound", "0.5")
    with pytest.raises(InputError, match="cannot set method.key.x"):
        sw.set_key("[method]\nkey = 1\n", "method.key.x", "2")
    # an array's entry is no key: it said "an inline table holds it" (batch trial, session 39)
    with pytest.raises(InputError, match=r"system\.A is an array: --set replaces it whole") as e:
        sw.set_key("[system]\nA = [[1, 2], [3, 4]]\n", "system.A.0", "1")
    assert "inline table" not in str(e.value)


def test_point_text_of_the_shipped_spec_changes_exactly_the_swept_keys():
    text = SPEC.read_text(encoding="utf-8")
    new = sw.point_text(text, {"method.lambda": "0.97", "simulate.horizon": "200"})
    assert _changed(text, new) == {
        "method": (
            tomllib.loads(text)["method"],
            {**tomllib.loads(text)["method"], "lambda": 0.97},
        ),
        "simulate": (
            tomllib.loads(text)["simulate"],
            {**tomllib.loads(text)["simulate"], "horizon": 200},
        ),
    }
    assert "lambda = 0.97\n" in new  # the decimal as written: the spec stays exact


# -- running points ------------------------------------------------------------------------
def test_mixed_good_and_bad_points_each_get_their_row_and_exit_code():
    # 0.94, 0.95: infeasible (exit 1: spectral radius 0.95); 0.96: ok; 1.5: bad input (exit 2)
    rows = sw.sweep_rows(SPEC, ["method.lambda=[0.94, 0.95, 0.96, 1.5, 0.99]"])
    assert [r["point"] for r in rows] == [0, 1, 2, 3, 4]
    assert [r["method.lambda"] for r in rows] == [0.94, 0.95, 0.96, 1.5, 0.99]
    assert [r["exit_code"] for r in rows] == [1, 1, 0, 2, 0]
    assert [r["verdict"] for r in rows] == ["failed", "failed", "ok", "bad input", "ok"]
    assert "spectral radius" in rows[0]["message"]
    assert "[point 3]" in rows[3]["message"] and "lambda" in rows[3]["message"]
    # a bad-input row names the spec's method (it was "": session 22's note)
    assert [r["method"] for r in rows] == ["lyapunov"] * 5
    ok = rows[2]
    assert (ok["certified"], ok["numerical"], ok["failed"], ok["message"]) == (6, 0, 0, "")
    assert ok["lambda"] == 0.96 and 0.95 < ok["lambda_best"] < 0.951 and ok["mu"] > 0
    assert sw.exit_code(rows) == 2
    assert sw.exit_code([rows[2], rows[4]]) == 0


def test_simulated_points_carry_the_metrics():
    rows = sw.sweep_rows(SPEC, ["method.lambda=[0.96, 0.99]"], simulate=True)
    assert all(r["exit_code"] == 0 for r in rows)
    for r in rows:
        assert r["rmse.x1"] > 0 and r["final_error_norm"] >= 0 and r["simulate_s"] >= 0
    # same gain L, same scenario: the trajectories do not depend on λ
    assert rows[0]["rmse.x1"] == rows[1]["rmse.x1"]


def test_simulate_without_a_simulate_table_is_bad_input_before_any_work(tmp_path: Path):
    text = SPEC.read_text(encoding="utf-8").split("[simulate]")[0]
    p = tmp_path / "s.toml"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(InputError, match=r"\[simulate\] is missing"):
        sw.plan(p, ["method.lambda=0.97"], simulate=True)


def test_options_are_checked_against_each_swept_method(tmp_path: Path):
    """With ``method.key`` swept, every point's method reads the options: ``runs`` is a
    lyapunov option, so a grid that also has a method without it is refused at once."""
    p = tmp_path / "s.toml"
    p.write_text(SPEC.read_text(encoding="utf-8"), encoding="utf-8")
    sw.plan(p, ["method.lambda=0.97"], simulate=True, options={"runs": "2"})
    tasks = sw.plan(p, ["method.key=['lyapunov', 'set-invariant']"], simulate=True)[1]
    with pytest.raises(InputError, match="--option runs: not an option of method 'set-inv"):
        sw.check_options(tasks, True, {"runs": "2"})
    sw.check_options(tasks, True, {"time_limit": "60"})  # an option of both


def test_api_sweep_returns_a_dataframe():
    pd = pytest.importorskip("pandas")
    from obsdesign import api

    df = api.sweep(SPEC, {"method.lambda": [0.96, 0.98]})
    assert isinstance(df, pd.DataFrame)
    assert list(df["method.lambda"]) == [0.96, 0.98]
    assert list(df.columns[:4]) == ["point", "method.lambda", "verdict", "exit_code"]
    import obsdesign

    assert list(obsdesign.sweep(SPEC, ["method.lambda=0.97"])["exit_code"]) == [0]


# -- the command line ------------------------------------------------------------------------
def test_cli_sweep_writes_csv_jsonl_and_plot(tmp_path: Path):
    out = tmp_path / "t.csv"
    png = tmp_path / "p.png"
    r = runner.invoke(
        app,
        [
            "sweep", str(SPEC), "--set", "method.lambda=0.95:0.99:5",
            "--set", "method.rate_tol=[0.0001, 0.001]",
            "-o", str(out), "--plot", str(png), "--y", "mu", "--quiet",
        ],
    )  # fmt: skip
    assert r.exit_code == 1, r.output  # λ = 0.95 is infeasible: the worst row
    with open(out, encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 10 and rows[0]["method.lambda"] == "0.95"
    assert [x["exit_code"] for x in rows] == ["1", "1"] + ["0"] * 8
    assert png.stat().st_size > 1000
    assert "swept: 10 points, 8 ok, 2 not ok (worst exit 1)" in r.output
    jl = tmp_path / "t.jsonl"
    r = runner.invoke(app, ["sweep", str(SPEC), "--set", "method.lambda=[0.97]", "-o", str(jl)])
    assert r.exit_code == 0, r.output
    lines = jl.read_text(encoding="utf-8").splitlines()
    assert len(lines) == 1 and json.loads(lines[0])["certified"] == 6


def test_cli_sweep_format_json_prints_only_data(tmp_path: Path):
    r = runner.invoke(
        app, ["sweep", str(SPEC), "--set", "method.lambda=[0.96,0.98]", "--format", "json"]
    )
    assert r.exit_code == 0
    rows = json.loads(r.stdout)
    assert [x["method.lambda"] for x in rows] == [0.96, 0.98]


def test_cli_sweep_parquet(tmp_path: Path):
    pq = pytest.importorskip("pyarrow.parquet")
    out = tmp_path / "t.parquet"
    r = runner.invoke(
        app, ["sweep", str(SPEC), "--set", "method.lambda=[0.94, 0.97]", "-o", str(out), "-q"]
    )
    assert r.exit_code == 1
    t = pq.read_table(out).to_pylist()
    assert [x["exit_code"] for x in t] == [1, 0] and t[1]["certified"] == 6


@pytest.mark.parametrize(
    "extra, msg",
    [
        (["-o", "{spec}"], "unknown table format"),
        (["-o", "{tmp}/t.xlsx"], "unknown table format"),
        (["--plot", "{tmp}/p.png"], "--plot needs --y"),
        (["--y", "mu"], "give --plot"),
        (["--plot", "{tmp}/p.png", "--y", "nope"], "--y nope: not a column"),
        (["--workers", "0"], "positive number"),
        (["--workers", "100000"], "start a Dask cluster"),  # was still starting after 120 s
        (["--workers", "2", "--scheduler", "tcp://h:1"], "exclude each other"),
        (["--scheduler", "localhost"], "tcp://HOST"),
        (["--set", "method.lambda=1"], "given twice"),
        # --option was ignored unread without --simulate, and with it a bad one was found
        # point by point after design and verify (docs trial, session 31)
        (["--option", "bogus=1"], "need --simulate"),
        (["--simulate", "--option", "bogus=1"], "--option bogus: not an option"),
        (["--simulate", "--option", "runs=0"], "--option runs"),
    ],
)
def test_cli_sweep_refuses_before_any_work(tmp_path: Path, extra: list[str], msg: str):
    spec = tmp_path / "s.toml"
    spec.write_text(SPEC.read_text(encoding="utf-8"), encoding="utf-8")
    before = spec.read_bytes()
    args = [a.format(spec=spec, tmp=tmp_path) for a in extra]
    r = runner.invoke(app, ["sweep", str(spec), "--set", "method.lambda=0.97", *args])
    assert r.exit_code == 2, r.output
    assert msg in r.stderr
    assert spec.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


def test_cli_sweep_refuses_the_spec_itself_as_output(tmp_path: Path):
    spec = tmp_path / "s.csv"  # a spec whose name looks like a table
    spec.write_text(SPEC.read_text(encoding="utf-8"), encoding="utf-8")
    r = runner.invoke(app, ["sweep", str(spec), "--set", "method.lambda=0.97", "-o", str(spec)])
    assert r.exit_code == 2 and "input file itself" in r.stderr
    assert spec.read_text(encoding="utf-8") == SPEC.read_text(encoding="utf-8")


def test_workers_without_dask_say_how_to_install_it(monkeypatch: pytest.MonkeyPatch):
    import obsdesign.distributed as dist

    monkeypatch.setattr(dist, "dask_available", lambda: False)
    for cmd in (
        ["sweep", str(SPEC), "--set", "method.lambda=0.97", "--workers", "2"],
        ["check", str(SPEC), "--workers", "2"],
    ):
        r = runner.invoke(app, cmd)
        assert r.exit_code == 2
        assert "pip install 'obsdesign[distributed]'" in r.stderr


def test_a_spec_too_deep_to_edit_is_bad_input(tmp_path: Path):
    """A dotted key 2,000 levels deep made the sweep's TOML edit check overflow the stack
    (RecursionError, exit 3: CLI fuzzer): exit 2, one line naming the file."""
    spec = tmp_path / "s.toml"
    spec.write_text(SPEC.read_text(encoding="utf-8") + "\n" + ".".join(["a"] * 2000) + " = 1\n")
    r = runner.invoke(app, ["sweep", str(spec), "--set", "method.lambda=0.96"])
    assert r.exit_code == 2, r.output
    assert "nested too deeply" in r.stderr and str(spec) in r.stderr


def test_a_value_of_too_many_digits_is_bad_input_naming_the_key() -> None:
    """A 5000-digit ``--set`` value (CLI) or integer (API) was an internal failure: Python's
    int-to-text limit raised a plain ValueError (exit 3; outsider trial, session 22). A
    value too long for that limit is kept as written and its point is a bad-input row naming
    the key (the first point's edit is checked before any work: exit 2 for the sweep); an
    API integer that cannot even be written is refused up front."""
    big = "7" * 5000
    assert sw.parse_axis("method.lambda=" + big).values == (big,)
    with pytest.raises(InputError, match=r"\[method\.lambda\] has a number with more than 1000"):
        sw.sweep_rows(SPEC, ["method.lambda=" + big])
    rows = sw.sweep_rows(SPEC, [f"method.lambda=[0.98, {big}]"])
    assert [r["exit_code"] for r in rows] == [0, 2]
    assert "[method.lambda] has a number with more than 1000 digits" in rows[1]["message"]
    with pytest.raises(InputError, match="at least 5000 digits, above the limit of 1000"):
        sw.parse_grid({"method.lambda": [10**5000]})


def test_a_nan_value_is_set_and_refused_by_the_spec_loader_in_its_row() -> None:
    """``--set method.lambda=nan`` said "an inline table or an array of tables holds it" for a
    plain key (the edit check compared nan != nan; outsider trial, session 22). The nan is
    set, and its point is a bad-input row, as inf is."""
    text = SPEC.read_text(encoding="utf-8")
    assert "lambda = nan" in sw.point_text(text, {"method.lambda": "nan"}, "s.toml")
    rows = sw.sweep_rows(SPEC, ["method.lambda=[nan, 0.98]"])
    assert [r["exit_code"] for r in rows] == [2, 0]
    assert "inline table" not in rows[0]["message"]


def test_a_plot_of_a_sweep_with_no_ok_point_is_all_gaps(tmp_path: Path) -> None:
    """Every point infeasible with ``--plot --y mu`` (outsider trial, session 22): the whole
    sweep ran, then "--y mu: not a column" and exit 2. A column known before the run is a
    column: the plot is written (all gaps) and the exit code is the worst row's (1). A text
    column (--y message) is refused before any work."""
    plot = tmp_path / "p.png"
    args = ["sweep", str(SPEC), "--set", "method.lambda=0.90:0.93:2", "--plot", str(plot)]
    r = CliRunner().invoke(app, [*args, "--y", "mu", "-q"])
    assert r.exit_code == 1, r.output
    assert plot.exists() and "worst exit 1" in r.output
    plot.unlink()
    r = CliRunner().invoke(app, [*args, "--y", "message", "-q"])
    assert r.exit_code == 2 and "a column of text" in r.output and not plot.exists()


def test_a_list_item_with_an_escaped_quote_is_one_item() -> None:
    """``--set 'title=["a\\"b", c]'`` was refused as "unbalanced brackets or quotes" although
    TOML reads it (outsider trial, session 22): in a basic string a backslash escapes the next
    character; a literal string ('...') has no escapes."""
    axis = sw.parse_axis(r'title=["a\"b", c, "x\\", ' + r"'lit\', 2]")
    assert axis.values == (r'"a\"b"', '"c"', r'"x\\"', r"'lit\'", "2")
    assert [tomllib.loads(f"v = {v}")["v"] for v in axis.values] == ['a"b', "c", "x\\", "lit\\", 2]


def test_integer_summary_parameters_stay_integers() -> None:
    """Sweep rows (so CSV and parquet) gave set-invariant's ``facets`` as 6.0 and
    ``iterations`` as 2.0 (outsider trial, session 22): an integer parameter is an int."""
    rows = sw.sweep_rows(ROOT / "specs" / "dorea-pimenta-7-1.toml", ["method.lambda=[0.9]"])
    assert rows[0]["exit_code"] == 0
    assert type(rows[0]["facets"]) is int and type(rows[0]["iterations"]) is int
    assert isinstance(rows[0]["contractivity"], float)


def test_hostile_set_values_are_bad_input() -> None:
    """A 3000-deep list value (RecursionError in the TOML parser) and a 5000-digit number of
    values (past Python's int-string limit) were internal failures, exit 3 (hostile-input
    trial, session 24): both are InputError naming the --set key."""
    with pytest.raises(InputError, match="method.L: the value is nested too deeply"):
        sw.parse_axis("method.L=" + "[" * 3000 + "1" + "]" * 3000)
    with pytest.raises(InputError, match="5000-digit number of values"):
        sw.parse_axis("method.lambda=0.9:0.99:" + "1" * 5000)
    assert len(sw.parse_axis("method.lambda=0.9:0.99:0000000000000003").values) == 3


def test_a_set_key_deeper_than_a_spec_may_nest_is_refused_at_once() -> None:
    """A 3000-part dotted key ran past 60 s before any check (hostile-input trial, session
    24): more parts than max_depth is bad input, before anything else."""
    with pytest.raises(InputError, match="3000 parts, deeper than a spec may nest"):
        sw.parse_axis(".".join(["a"] * 3000) + "=1")


def test_set_key_finds_the_comment_after_a_value_full_of_hashes() -> None:
    """The value's end was searched with one TOML parse per '#', quadratic (20,000 '#' in a
    string ran past 60 s; hostile-input trial, session 24): a binary search now, since
    every '#' after the value's end lies in the comment. The comment is kept, '#' inside
    strings are not taken for it."""
    text = '[method]\nkey = "x"\nlam = "a#b#' + "#" * 3000 + '"  # keep # this\nz = 1\n'
    out = sw.set_key(text, "method.lam", "5")
    assert "lam = 5  # keep # this\nz = 1" in out
    assert sw.set_key("[m]\nv = 1#c\n", "m.v", "2") == "[m]\nv = 2#c\n"
    assert sw.set_key('[m]\nv = "#"\n', "m.v", "2") == "[m]\nv = 2\n"


def test_set_key_finds_the_end_of_a_long_multiline_value_in_linear_time(monkeypatch) -> None:
    """A multi-line value's end was searched with one TOML parse per line, quadratic (3.4 s
    for a 100-row A written a row per line; 3000 lines of one number each: 3000 parses of a
    growing text). The lexer (spec/tomltext.py) finds it in one pass, without parsing; the
    value is replaced whole and the keys after it kept."""
    calls = []
    real = tomllib.loads
    monkeypatch.setattr(sw.tomllib, "loads", lambda t, **k: calls.append(1) or real(t, **k))
    rows = ",\n".join(f"  {k}.5" for k in range(3000))
    text = f'[system]\nA = [\n{rows}\n]\nC = [[1]]\n[method]\nkey = "lyapunov"\n'
    out = sw.set_key(text, "system.A", "[[0.25]]")
    assert len(calls) < 10, len(calls)  # set_key's own checks of the edit
    assert real(out) == {"system": {"A": [[0.25]], "C": [[1]]}, "method": {"key": "lyapunov"}}


def test_set_key_multiline_span_is_not_fooled_by_a_key_named_like_the_old_span_key() -> None:
    """A later line redefining the key the old bisection parsed the span under broke it."""
    text = '[m]\nv = [\n  1,\n  2,\n]\nw = 3\n"obsdesign-sweep-value-span" = 4\nz = [\n 5\n]\n'
    out = sw.set_key(text, "m.v", "7")
    assert tomllib.loads(out) == {"m": {"v": 7, "w": 3, "obsdesign-sweep-value-span": 4, "z": [5]}}


def test_a_point_past_the_timeout_gets_its_row_and_the_others_keep_theirs(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """One hanging point cost every row of a sweep (hostile-input trial, session 24):
    ``timeout`` bounds each point as ``check --timeout`` does each spec; the slow point is
    exit 3 "not finished", the fast one keeps its row. The second point's design hangs (a
    stand-in: the nested-sin input that used to take seconds, its input range bisected to the
    whole budget, is now refuted at once — session 43)."""
    import time

    from obsdesign import api as _api

    spec = Path(__file__).resolve().parents[1] / "specs" / "hernandez-garcia-example.toml"
    real = _api.design

    def hangs(sp, *a, **k):  # noqa: ANN001, ANN002, ANN003, ANN202
        if "[point 1]" in str(getattr(sp, "file", "")):
            while True:
                time.sleep(0.05)
        return real(sp, *a, **k)

    monkeypatch.setattr(_api, "design", hangs)
    grid = ['system.u=[["t/3 - floor(t/3)"], ["t/4 - floor(t/4)"]]']
    rows = sw.sweep_rows(spec, grid, timeout=1.0)
    assert [r["exit_code"] for r in rows] == [0, 3]
    assert rows[1]["message"].startswith("not finished within 1 s")
    # the Python API's sweep takes it too (a TypeError: batch trial, session 35)
    from obsdesign import api

    out = api.sweep(spec, grid, timeout=1.0)
    codes = list(out["exit_code"]) if hasattr(out, "columns") else [r["exit_code"] for r in out]
    assert codes == [0, 3]
    # named as check's row names it (it was empty: Dask trial, session 29)
    assert rows[1]["method"] == rows[0]["method"] == "search-space"


def test_a_lost_point_names_its_method(tmp_path: Path) -> None:
    """A point lost with a dying worker had an empty method (Dask trial, session 29): its
    spec's [method] key when it is a known method, else ""."""
    text = '[system]\nA = [[0.5]]\nC = [[1]]\n[method]\nkey = "lyapunov"\n'
    spec = tmp_path / "s.toml"
    spec.write_text(text)
    _, tasks = sw.plan(spec, ["system.A=[[[0.1]], [[0.2]]]"])
    assert [sw.task_method(t) for t in tasks] == ["lyapunov", "lyapunov"]
    spec.write_text(text.replace("lyapunov", "lyapunovv"))
    _, tasks = sw.plan(spec, ["system.A=[[[0.1]]]"])
    assert sw.task_method(tasks[0]) == ""


def test_set_key_is_not_fooled_by_a_multiline_string_further_down() -> None:
    """The bisection over lines assumed that every prefix past the value's end parses; a
    multi-line string below made that false-true-false-true and the edit deleted the lines
    in between: 19 of the 288 keys of the shipped specs were refused, e.g. ``title`` of the
    constrained Lyapunov spec (outsider trial, session 26)."""
    text = 'title = "t"\nreference = "r"\ndescription = """\na\n\nb = 1\n"""\n[m]\nk = 1\n'
    out = sw.set_key(text, "title", '"x"')
    assert tomllib.loads(out) == {
        "title": "x",
        "reference": "r",
        "description": "a\n\nb = 1\n",
        "m": {"k": 1},
    }


def test_set_key_does_not_take_a_matrix_row_for_a_table_header() -> None:
    """``  [1, 0]`` on a line of its own (the last row of a matrix) matched the header pattern,
    so the keys after it seemed outside [system] (outsider trial, session 26)."""
    text = '[system]\ntime = "discrete"\nA = [\n  [0, 1],\n  [1, 0]\n]\nC = [[1, 0]]\n'
    out = sw.set_key(text, "system.C", "[[0, 1]]")
    assert tomllib.loads(out)["system"] == {
        "time": "discrete",
        "A": [[0, 1], [1, 0]],
        "C": [[0, 1]],
    }


def test_set_key_reads_triple_quotes_inside_a_literal_string_as_text() -> None:
    """``\"\"\"`` inside a single-quoted string started a "multi-line string" for the line
    scanner, which then skipped every header below (outsider trial, session 26)."""
    text = 'title = \'a """ in a literal string\'\n[method]\nlambda = 0.9\n'
    out = sw.set_key(text, "method.lambda", "0.97")
    assert tomllib.loads(out) == {"title": 'a """ in a literal string', "method": {"lambda": 0.97}}


@pytest.mark.parametrize(
    "path",
    sorted((Path(__file__).resolve().parents[1] / "specs").glob("*.toml")),
    ids=lambda p: p.stem,
)
def test_every_key_of_every_shipped_spec_can_be_set(path: Path) -> None:
    """Every leaf key of the shipped specs (outside arrays of tables) set to a new value of
    its own kind changes exactly that key (set_key's own comparison with the original)."""
    text = path.read_text(encoding="utf-8")

    def leaves(d: dict, pre: tuple = ()):
        for k, v in d.items():
            if isinstance(v, dict):
                yield from leaves(v, (*pre, k))
            else:
                yield (*pre, k), v

    n = 0
    for parts, v in leaves(tomllib.loads(text)):
        lit = '"zz"' if isinstance(v, str) else "[7]" if isinstance(v, list) else "7"
        out = sw.set_key(text, ".".join(parts), lit, path.name)
        d = tomllib.loads(out)
        for p in parts:
            d = d[p]
        assert d == tomllib.loads(f"x = {lit}")["x"]
        n += 1
    assert n >= 10


def test_a_swept_value_a_double_cannot_hold_keeps_its_digits_in_the_row() -> None:
    """λ = 0.9999999999999999999999 certifies as written, but its row showed the nearest
    double, 1.0, which the spec loader refuses (outsider trial, session 26): a value the
    double's shortest repr does not equal is shown as its literal; others as numbers."""
    assert sw._value("0.9999999999999999999999") == "0.9999999999999999999999"
    assert sw._value("0.1") == 0.1 and isinstance(sw._value("0.1"), float)
    assert sw._value("1_000.5") == 1000.5 and sw._value("1e-3") == 0.001
    assert sw._value("7") == 7 and sw._value('"x"') == "x"
    rows = sw.sweep_rows(SPEC, ["method.lambda=[0.9999999999999999999999, 0.97]"])
    assert [r["method.lambda"] for r in rows] == ["0.9999999999999999999999", 0.97]


def _random_document():
    """A strategy of TOML documents: tables of keys whose values are strings of every kind
    (with '#', brackets, quotes and newlines inside), numbers and nested multi-line arrays
    with comments; comment and blank lines between; header-like text inside values."""
    from hypothesis import strategies as st

    from tests.test_spec_tomltext import _values

    names = st.sampled_from(["a", "b", "c", "system", "method"])
    stmt = st.tuples(names, _values).map(lambda kv: f"{kv[0]} = {kv[1]}")
    filler = st.sampled_from(["", "# [not.a.table]", "  # x = 1", ""])
    body = st.lists(st.one_of(stmt, filler), max_size=5)
    section = st.tuples(st.sampled_from(["", "[t]", "[u]", "[t.v]", "[[w]]"]), body)
    return st.lists(section, min_size=1, max_size=4).map(
        lambda secs: (
            "\n".join(h + "\n" + "\n".join(b) if h else "\n".join(b) for h, b in secs) + "\n"
        )
    )


def _leaves(d: dict, pre: tuple = ()):
    for k, v in d.items():
        if isinstance(v, dict):
            yield from _leaves(v, (*pre, k))
        elif not (isinstance(v, list) and v and all(isinstance(x, dict) for x in v)):
            yield (*pre, k)


def test_set_key_on_random_documents_changes_exactly_that_key() -> None:
    """Property: in any valid document, setting any existing key (outside arrays of tables)
    or a new key of an existing table gives exactly the document with that change."""
    from hypothesis import HealthCheck, assume, given, settings

    @settings(max_examples=200, deadline=None, suppress_health_check=list(HealthCheck))
    @given(text=_random_document())
    def run(text: str) -> None:
        try:
            doc = tomllib.loads(text)
        except tomllib.TOMLDecodeError:
            assume(False)
            return
        for parts in [*_leaves(doc), ("t", "fresh"), ("fresh",)]:
            if parts[0] == "t" and "t" not in doc:
                continue
            out = tomllib.loads(sw.set_key(text, ".".join(parts), "[7, 'x # y']"))
            want = json.loads(json.dumps(doc))
            d = want
            for p in parts[:-1]:
                d = d.setdefault(p, {})
            d[parts[-1]] = [7, "x # y"]
            assert json.loads(json.dumps(out)) == want, (text, parts)

    run()


def test_parquet_of_a_column_mixing_text_and_numbers(tmp_path: Path) -> None:
    """A swept value a double cannot show is text beside numbers; pyarrow refused that
    column (ArrowTypeError, exit 3; re-run trial, session 26). Such a column is written as
    text; one-kind columns keep their type."""
    pq = pytest.importorskip("pyarrow.parquet")
    rows = [
        {"point": 0, "method.lambda": "0.9999999999999999999999", "exit_code": 0},
        {"point": 1, "method.lambda": 0.97, "exit_code": 0},
        {"point": 2, "method.lambda": None, "exit_code": 2},
    ]
    out = tmp_path / "t.parquet"
    sw.write_table(out, rows)
    got = pq.read_table(out).to_pydict()
    assert got["method.lambda"] == ["0.9999999999999999999999", "0.97", None]
    assert got["exit_code"] == [0, 0, 2] and got["point"] == [0, 1, 2]


def test_a_plot_leaves_inconclusive_points_as_gaps() -> None:
    """An exit-4 row (nothing certified) was drawn as a value (session 28): only exit 0 is."""
    rows = [
        {"method.lambda": 0.96, "mu": 10.0, "exit_code": 0},
        {"method.lambda": 0.97, "mu": 99.0, "exit_code": 4},
        {"method.lambda": 0.98, "mu": 5.0, "exit_code": 1},
    ]
    pts = sw.plot_groups(rows, [], "method.lambda", "mu")[()]
    assert pts[0] == (0.96, 10.0)
    assert [math.isnan(p[1]) for p in pts] == [False, True, True]


def test_sweep_tables_mark_rounded_values_and_matrices_are_json_lists() -> None:
    """A certified λ = 0.9999999999999999999999 was a bare "1" in the sweep table, the ISS
    bound 24842821.6875 a bare "2.48428e+07" (below the bound), and stubborn's K a quoted
    numpy text with literal "\\n" (sweep, import and check trial, session 28)."""
    import pickle

    from obsdesign.cli_commands import _md_value, _sweep_cell

    lyap = ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml"
    rows = sw.sweep_rows(lyap, ["method.lambda=[0.96, 0.9999999999999999999999]"])
    exact, near = rows
    assert isinstance(near["lambda"], sw.ExactFloat) and near["lambda"] == 1.0
    assert _sweep_cell(near["lambda"]) == "≈1" and _md_value(near["lambda"]) == "≈1.0"
    assert _sweep_cell(exact["lambda"]) == "0.96"  # 24/25 shown as itself
    assert _md_value(exact["lambda"]) == "0.96"
    # (μ values since session 38: 10⁻⁶ above the float μ, lyapunov.design.ISS_MU_REL)
    assert _sweep_cell(exact["mu"]) == "≈2.48428e+07" and exact["mu"] == 24842846.5
    # an exact dyadic μ = 233000741/1048576: its double's shortest text is not its value (it
    # showed bare in Markdown: re-check trial, session 28)
    assert near["mu"].exact == "233000741/1048576"
    assert _md_value(near["mu"]) == "≈222.2068223953247"
    assert _md_value(exact["mu"]) == "24842846.5"
    assert _sweep_cell(1.5) == "1.5" and _sweep_cell(float("nan")) == "nan"
    again = pickle.loads(pickle.dumps(near["lambda"]))
    assert isinstance(again, sw.ExactFloat) and again.exact == near["lambda"].exact
    assert json.dumps(near["lambda"]) == "1.0"
    stub = sw.sweep_rows(
        ROOT / "specs" / "astolfi-stubborn-example1.toml", ["method.lambda_fraction=[0.5]"]
    )[0]
    assert stub["exit_code"] == 0
    assert json.loads(stub["K"]) == [[-2.5623020538914716], [8.402663141750963]]


def test_plot_groups_keeps_groups_apart_and_skips_only_bad_rows() -> None:
    """Mutation review 28: obsdesign.sweep.x_plot_groups__mutmut_4 (the group key read as ``r.get(None)``: every
    curve merged into one) and _19 (``continue`` -> ``break``: a row without a numeric x
    ended the plot, later points lost)."""
    from obsdesign import sweep as sw

    rows = [
        {"a": 0.1, "b": 1, "y": 1.0, "exit_code": 0},
        {"a": "bad", "b": 1, "y": 9.0, "exit_code": 0},
        {"a": 0.2, "b": 1, "y": 2.0, "exit_code": 0},
        {"a": 0.1, "b": 2, "y": 3.0, "exit_code": 0},
    ]
    assert sw.plot_groups(rows, ["b"], "a", "y") == {
        (1,): [(0.1, 1.0), (0.2, 2.0)],
        (2,): [(0.1, 3.0)],
    }


def test_scalar_cells_of_non_finite_text_and_objects() -> None:
    """Mutation review 28: obsdesign.sweep.x__scalar__mutmut_19 (``isinstance(v0, fmpq) and isfinite(f) or
    fmpq(...)``: a float inf / nan parameter raised OverflowError / ValueError), _8 (``v =
    None``: a text parameter became '"abc"'), _15 (``json.dumps(None)``: "null"), _16/_18
    (no ``default=str``: TypeError on an fmpq inside) and _17 (``json.dumps(default=str)``:
    TypeError)."""
    from flint import fmpq

    from obsdesign import sweep as sw
    from obsdesign.params import Parameters

    p = Parameters({"inf": math.inf, "nan": math.nan, "s": "abc", "d": {"q": fmpq(1, 3)}})
    got = sw._scalar(p, "inf")
    assert got == math.inf and type(got) is float
    assert math.isnan(sw._scalar(p, "nan"))
    assert sw._scalar(p, "s") == "abc"
    assert sw._scalar(p, "d") == '{"q": "1/3"}'


def test_sweep_cell_of_none_and_of_an_integer() -> None:
    """Mutation review 28: obsdesign.cli_commands.x__sweep_cell__mutmut_2 (None shown "XXXX") and _21 (every
    non-float shown "None"): an empty cell stays empty, facets 6 is "6"."""
    from obsdesign.cli_commands import _sweep_cell

    assert _sweep_cell(None) == ""
    assert _sweep_cell(6) == "6" and _sweep_cell("ok") == "ok"


def test_plot_marks_points_that_are_not_ok_over_the_whole_range(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Failed points at an end of the range were off the axis: the README's sweep drew
    0.96 … 0.99 of 0.90 … 0.99 and nothing said six points failed (outsider trial, session
    29). The x range covers every swept value and the failed ones are marked ×."""
    from obsdesign.simulate import plot as simplot

    figs = []
    monkeypatch.setattr(simplot, "save_figure", lambda fig, path, dpi: figs.append(fig))
    axes = sw.parse_grid(["method.lambda=0.90:0.99:10"])
    rows = [
        {"method.lambda": 0.9 + i / 100, "exit_code": 0 if i >= 6 else 1, "mu": 10.0 - i}
        for i in range(10)
    ]
    sw.plot_sweep(rows, axes, "mu", tmp_path / "p.png")
    (ax,) = figs[0].axes
    lo, hi = ax.get_xlim()
    assert lo < 0.90 and hi > 0.99
    marks = [ln for ln in ax.lines if ln.get_label().startswith("not ok")]
    assert len(marks) == 1 and list(marks[0].get_xdata()) == pytest.approx(
        [0.9 + i / 100 for i in range(6)]
    )
    figs.clear()
    sw.plot_sweep([dict(r, exit_code=0) for r in rows], axes, "mu", tmp_path / "q.png")
    assert not [ln for ln in figs[0].axes[0].lines if ln.get_label().startswith("not ok")]


def test_a_y_column_no_row_has_is_refused_before_the_table_is_written(tmp_path: Path) -> None:
    """``sweep --simulate -o T --plot P --y bogus``: the columns of a simulated sweep are
    known after the run only, and the table was written before --y was found wrong (exit 2
    with -o replaced; output trial, session 30). --y is checked before -o is written."""
    out, png = tmp_path / "t.csv", tmp_path / "p.png"
    out.write_text("old\n")
    r = CliRunner().invoke(
        app,
        [
            "sweep", str(SPEC), "--simulate", "--set", "method.lambda=[0.96, 0.97]",
            "-o", str(out), "--plot", str(png), "--y", "bogus", "-q",
        ],
    )  # fmt: skip
    assert r.exit_code == 2 and "--y bogus" in r.output, r.output
    assert out.read_text() == "old\n" and not png.exists()


@pytest.mark.parametrize("count", ["-1", "+0", "-00000000000000000000005"])
def test_a_range_with_a_negative_or_zero_count_says_so(count: str) -> None:
    """`a:b:-1` said "'0.96:0.97:-1' is not a TOML value" (hostile-input trial, session 38):
    the count is read with its sign and the message names it; `:lin` is the default spacing."""
    from obsdesign.errors import InputError

    with pytest.raises(InputError, match="the number of values must be at least 1, got "):
        sw.parse_grid([f"method.lambda=0.96:0.97:{count}"])
    assert sw.parse_grid(["a.x=1:2:3:lin"])[0].values == sw.parse_grid(["a.x=1:2:3"])[0].values


def test_a_spec_with_a_byte_order_mark_gets_the_loaders_message(tmp_path: Path) -> None:
    """design, check and simulate name the BOM; sweep said "is not valid TOML (Invalid
    statement …)" (CLI trial, session 40)."""
    spec = tmp_path / "bom.toml"
    spec.write_bytes(b"\xef\xbb\xbf" + SPEC.read_bytes())
    res = CliRunner().invoke(app, ["sweep", str(spec), "--set", "method.rate=0.9"])
    assert res.exit_code == 2 and "byte-order mark" in res.output, res.output


def test_ok_rows_without_a_value_are_gaps_not_failures(monkeypatch, tmp_path) -> None:
    """--y alpha of a discrete-time spec (no alpha), or mu where iss_gain = false: every ok
    row was marked × "not ok (a row with exit ≠ 0)" (sweep review, session 42). Only rows
    with exit ≠ 0 are marked; the CLI warns that the ok rows without a value are gaps."""
    from obsdesign.simulate import plot as splot

    figs = []
    monkeypatch.setattr(splot, "save_figure", lambda fig, path, **kw: figs.append(fig))
    rows = [
        {"a": 0.1, "exit_code": 0},
        {"a": 0.2, "y": 2.0, "exit_code": 0},
        {"a": 0.3, "exit_code": 1},
    ]
    sw.plot_sweep(rows, [sw.Axis("a", ("0.1", "0.2", "0.3"))], "y", tmp_path / "p.png")
    (ax,) = figs[0].axes
    marks = [ln for ln in ax.get_lines() if ln.get_label().startswith("not ok")]
    assert len(marks) == 1 and list(marks[0].get_xdata()) == [0.3]
    assert sw.missing_y(rows, "y") == 1
    lyap = ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml"
    res = CliRunner().invoke(
        app,
        ["sweep", str(lyap), "--set", "method.lambda=[0.96, 0.97]", "--plot",
         str(tmp_path / "q.png"), "--y", "alpha", "-q"],
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    assert "2 ok row(s) have no value of --y alpha" in res.stderr


def test_a_trailing_comma_ends_a_value_list_as_in_toml() -> None:
    """`--set 'method.lambda=[0.96,]'` was "empty item" although TOML reads [0.96,] as [0.96]
    (sweep review, session 42); empty items elsewhere stay refused."""
    assert sw.parse_axis("method.lambda=[0.96,]").values == ("0.96",)
    assert sw.parse_axis("method.lambda=[0.96, 0.97,]").values == ("0.96", "0.97")
    for bad in ("[0.96,,]", "[,]", "[0.96,,0.97]"):
        with pytest.raises(InputError, match="empty item"):
            sw.parse_axis(f"method.lambda={bad}")


def test_a_point_with_long_exact_values_is_verified_with_its_own_digit_limit(
    tmp_path: Path,
) -> None:
    """A sweep row verifies its own report as check does (``api.verify_own``): a Q entry of
    1e-300 made ~2,200-digit exact values, and the row was "exit 2 bad input" (CLI review,
    session 44)."""
    from obsdesign import api

    root = Path(__file__).resolve().parents[1]
    text = (root / "specs" / "dorea-pimenta-7-2.toml").read_text(encoding="utf-8")
    assert "[0.2681, 0.7595, -0.0851]" in text and "lambda = 1\n" in text
    spec = tmp_path / "q.toml"
    spec.write_text(text.replace("[0.2681, 0.7595, -0.0851]", "[1e-300, 0.7595, -0.0851]"))
    rows = api.sweep(spec, ["method.lambda=1:1:1"])
    assert list(rows["exit_code"]) == [0], rows.to_dict("records")


@pytest.mark.parametrize("width", [40, 60, 100, 200])
def test_a_narrow_sweep_table_is_a_paragraph_a_point_with_every_value_whole(width: int) -> None:
    """At --width 40 the table folded headers and values mid-word ("metho / d.lam / bda",
    "faile / d"; CLI review 44) and at 100 with --simulate it squeezed or cropped columns:
    when the columns cannot all be whole, each point is a paragraph of key=value items
    wrapped at spaces, every value whole and on one line; a wide terminal keeps the table."""
    r = runner.invoke(
        app, ["sweep", str(SPEC), "--set", "method.lambda=[0.9, 0.96]", "--width", str(width)]
    )
    assert r.exit_code == 1, r.output
    lines = [x for x in r.stdout.splitlines() if not x.startswith("swept: ")]
    assert all(len(x) <= width for x in lines), r.stdout
    if width >= 200:
        assert any("┃ point ┃ method.lambda ┃ verdict ┃" in x for x in lines), r.stdout
        return
    assert all(x == x.rstrip() for x in lines), r.stdout
    text = " ".join(x.strip() for x in lines)
    for item in (
        "method.lambda=0.9 ",
        "verdict=failed",
        "exit_code=1",
        "method.lambda=0.96",
        "verdict=ok",
        "certified=6",
        "lambda_best=0.9501",
        "mu=≈2.48428e+07",
    ):
        assert item in text, (item, r.stdout)
    assert [x for x in lines if x.startswith("point ")] == ["point 0", "point 1"]
    assert "spectral radius ≈ 0.95" in text


def test_a_wide_character_value_is_measured_in_terminal_cells() -> None:
    """A CJK swept title (two cells a character) was measured in characters: at --width 170
    the table folded it mid-value, and the paragraphs were 56 cells wide at --width 40
    (re-check review 45). Widths are terminal cells now: no line wider than --width."""
    from rich.cells import cell_len

    title = "日本語のタイトル" * 3
    for width in (40, 100, 170):
        r = runner.invoke(
            app,
            [
                "sweep",
                str(SPEC),
                "--set",
                f'title=["{title}"]',
                "--set",
                "method.lambda=[0.955, 0.9]",
                "--width",
                str(width),
            ],
        )
        lines = [x for x in r.stdout.splitlines() if not x.startswith("swept: ")]
        assert r.exit_code == 1 and all(cell_len(x) <= width for x in lines), (width, r.stdout)
        assert title in "".join(x.strip() for x in lines).replace("title=", ""), r.stdout


def test_the_api_names_a_bad_spec_or_grid_argument() -> None:
    """sweep(123, ...) was a bare AttributeError, and an empty generator as the grid swept one
    unswept point with verdict ok where [] is refused (API review 45): both are InputErrors;
    a non-empty generator and one KEY=VALUES text sweep."""
    for spec in (123, {"a": 1}):
        with pytest.raises(InputError, match="sweep: spec must be a path or a Spec"):
            sw.sweep_rows(spec, {"method.lambda": [0.96]})
    for grid in ([], (t for t in []), [3]):
        with pytest.raises(InputError, match="sweep: (no --set|expected KEY=VALUES)"):
            sw.sweep_rows(SPEC, grid)
    rows = sw.sweep_rows(SPEC, (t for t in ["method.lambda=[0.96, 0.97]"]))
    assert [r["exit_code"] for r in rows] == [0, 0]
    assert len(sw.sweep_rows(SPEC, "method.lambda=0.96")) == 1


@pytest.mark.parametrize("width", [40, 250])
def test_control_characters_of_a_swept_value_are_escapes_in_both_layouts(width: int) -> None:
    """The paragraph layout printed a swept title's ESC colour sequence raw (it reached the
    terminal) and its newline broke the paragraph (CLI review 45); the table escaped them.
    Both layouts print them as escapes now."""
    r = runner.invoke(
        app,
        [
            "sweep",
            str(SPEC),
            "--set",
            'title=["red \\u001b[31mX\\u001b[0m and\\nnew"]',
            "--set",
            "method.lambda=[0.96]",
            "--width",
            str(width),
        ],
    )
    assert r.exit_code == 0, r.output
    assert "\x1b" not in r.stdout and "red \\x1b[31mX\\x1b[0m and\\nnew" in r.stdout, r.stdout


def test_a_swept_value_past_the_float_range_is_its_literal() -> None:
    """A swept 1e400 was recorded as inf in the rows (text, json, csv), a real inf point's
    look (CLI review 45): the cell is the literal as written; inf itself stays inf."""
    assert sw._value("1e400") == "1e400" and sw._value("-1e400") == "-1e400"
    # an exponent past Decimal's own range read as 0.0 (re-check review 45)
    assert sw._value("0.9e-100000000000000000000") == "0.9e-100000000000000000000"
    assert sw._value("inf") == float("inf") and sw._value("0.5") == 0.5
    rows = sw.sweep_rows(SPEC, ["method.lambda=[1e400, 0.96]"])
    assert rows[0]["method.lambda"] == "1e400" and rows[0]["exit_code"] == 2
    assert rows[1]["method.lambda"] == 0.96 and rows[1]["exit_code"] == 0


def test_a_plot_skips_swept_values_past_the_float_range(tmp_path: Path) -> None:
    """sweep --plot with a swept 1e400 or inf was exit 3 "Axis limits cannot be NaN or Inf",
    no table and no plot, the sweep's own exit 2 lost (re-check review 45): such an x has no
    place on the axis and is left out; the plot is written and the exit code is the rows'."""
    out = tmp_path / "p.png"
    r = runner.invoke(
        app,
        [
            "sweep",
            str(SPEC),
            "--set",
            "method.lambda=[0.96, 0.97, 1e400]",
            "--plot",
            str(out),
            "--y",
            "certified",
        ],
    )
    assert r.exit_code == 2 and out.stat().st_size > 0, r.output
    groups = sw.plot_groups(
        [{"a": 1e400, "y": 1, "exit_code": 0}, {"a": 0.5, "y": 2, "exit_code": 0}], [], "a", "y"
    )
    assert groups == {(): [(0.5, 2.0)]}


def test_width_folds_the_progress_bar_and_the_summary_line(tmp_path: Path):
    """--width 40 holds for the progress bar on stderr and the "swept:" line: the bar took
    the terminal's (or rich's) width and the line ran past the table's (session 45's note)."""
    import os
    import subprocess
    import sys

    from rich.cells import cell_len

    env = dict(os.environ, COLUMNS="200")
    cmd = [sys.executable, "-m", "obsdesign", "sweep", str(SPEC)]
    cmd += ["--set", "method.lambda=[0.9, 1.5]", "--width", "40"]
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=tmp_path, timeout=120)
    assert r.returncode == 2, r.stderr
    bar = [x for x in r.stderr.splitlines() if "failures" in x]
    assert bar and all(cell_len(x) <= 40 for x in bar), r.stderr
    out = r.stdout.splitlines()
    k = next(i for i, x in enumerate(out) if x.startswith("swept: "))
    assert out[k:] == ["swept: 2 points, 0 ok, 2 not ok (worst", "exit 2)"]
    assert all(cell_len(x) <= 40 for x in out), r.stdout


def test_the_sweep_api_refuses_a_grid_or_simulate_flag_of_another_type() -> None:
    """sweep(spec, None) and sweep(spec, 5) were bare TypeErrors, and simulate='no' simulated
    every point (CLI review 46)."""
    for grid in (None, 5):
        with pytest.raises(InputError, match="as the grid, got"):
            sw.sweep(SPEC, grid)
    for flag in ("no", 1, None):
        with pytest.raises(InputError, match="simulate: expected True or False"):
            sw.sweep(SPEC, ["method.lambda=0.97"], simulate=flag)


def test_a_spec_object_edited_after_loading_is_refused_by_sweep() -> None:
    """sweep() of a Spec whose system was replaced after loading swept its text, every row
    ok, while design refuses the object (API review 46). Refused the same way."""
    import dataclasses

    from obsdesign import api

    sp = api.load_spec(SPEC)
    sp.system = dataclasses.replace(sp.system, A=sp.system.C)
    with pytest.raises(InputError, match="was replaced or edited after loading"):
        sw.sweep(sp, ["method.lambda=[0.97]"])
    assert sw.sweep(api.load_spec(SPEC), ["method.lambda=[0.97]"]) is not None


def test_a_point_past_the_readers_range_names_the_spec_method() -> None:
    """A swept value past Decimal's range (1e999999999): its row's method was "" while every
    other bad-input row names the spec's method (CLI review 46)."""
    rows = sw.sweep_rows(SPEC, ["method.lambda=[1e999999999, 0.97]"])
    assert [r["exit_code"] for r in rows] == [2, 0]
    assert [r["method"] for r in rows] == ["lyapunov", "lyapunov"]


def test_set_of_a_table_or_into_an_array_says_so_without_tomllib_positions() -> None:
    """--set method=1 said tomllib's "Cannot overwrite a value (at line 15, column 8)" and
    --set system.A.0=1 "(at line 13, column 8)": positions in the text as edited, not the
    user's (CLI review 46). A table is named as one; positions are dropped."""
    with pytest.raises(InputError, match=r"cannot set method = 1: \[method\] is a table") as e:
        sw.plan(SPEC, ["method=1"])
    with pytest.raises(InputError, match="system.A is an array") as e2:
        sw.plan(SPEC, ["system.A.0=1"])
    assert "at line" not in str(e.value) and "at line" not in str(e2.value)
    with pytest.raises(InputError, match=r"\[method.lambda\] is a value, not a table"):
        sw.plan(SPEC, ["method.lambda.x=1"])


AOT = """[simulate.noise]  # the output disturbance
kind = "windows"

[[simulate.noise.windows]]
start = 151
stop = 153
value = [3]

[simulate.noise.windows.sub]
x = 1

[[simulate.noise.windows]]
start = 160
stop = 161
value = [1]

[method]
key = "lyapunov"
"""


def test_set_key_replaces_an_array_of_tables_whole() -> None:
    """windows written as [[simulate.noise.windows]] (the spec loader takes it) could not be
    swept: "an inline table holds it: write it as a [table]", wrong advice, and a key under
    it said tomllib's bare "Cannot overwrite a value" (re-check review 47). The whole key
    replaces every [[...]] block and its sub-tables; a key under it names the array."""
    new = sw.set_key(AOT, "simulate.noise.windows", "[{ start = 1, stop = 2, value = [3] }]")
    got = tomllib.loads(new)
    assert got["simulate"]["noise"] == {
        "kind": "windows",
        "windows": [{"start": 1, "stop": 2, "value": [3]}],
    }
    assert got["method"] == {"key": "lyapunov"} and "[[" not in new
    for sub in ("simulate.noise.windows.0.start", "simulate.noise.windows.sub.x"):
        with pytest.raises(
            InputError, match=r"\[\[simulate\.noise\.windows\]\] is an array of"
        ) as e:
            sw.set_key(AOT, sub, "3")
        # the advice is one point (outer brackets list the swept values; re-check review 47)
        assert "--set 'simulate.noise.windows=[[{ ... }, ...]]'" in str(e.value)
    # the table that holds it, and a sibling key, are edited as before
    assert (
        tomllib.loads(sw.set_key(AOT, "simulate.noise.kind", '"none"'))["simulate"]["noise"][
            "windows"
        ][1]["start"]
        == 160
    )
