"""The Python API: design, verify, simulate, check. The CLI is a thin shell over these."""

from __future__ import annotations

import hashlib
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from obsdesign.certify.claim import Claim, ClaimStatus, exact_claim
from obsdesign.errors import EXIT_OK, InputError, ObsdesignError, SpecError
from obsdesign.methods import get_method, method_keys
from obsdesign.methods.base import Method, Progress
from obsdesign.params import Parameters
from obsdesign.report.model import Report, write_atomic
from obsdesign.simulate.result import SimResult
from obsdesign.spec import Spec, read_spec, read_spec_text


# -- binding a spec to its method ----------------------------------------------------------
def method(key: str) -> Method:
    """The method object for ``key``; :class:`InputError` (with a suggestion) if unknown."""
    if key not in method_keys():
        raise InputError(
            f"unknown method '{key}'{_did_you_mean(key, method_keys())} "
            f"(known: {', '.join(method_keys())})"
        )
    return get_method(key)


def bind(spec: Spec) -> Spec:
    """Bind the spec's method: parse ``[method]`` into ``spec.options`` and the method's own
    ``[simulate]`` keys into ``spec.simulate.options``; check the generic contract (linear
    model present where the method needs it, no table the method does not read)."""
    if spec.options is not None:
        return spec
    mt = spec.method_table
    assert mt is not None
    if spec.method not in method_keys():
        raise mt.error(
            "key",
            f"expected one of {', '.join(method_keys())}; got {spec.method!r}"
            + _did_you_mean(spec.method, method_keys()),
        )
    m = get_method(spec.method)
    s = spec.system
    if m.needs_linear:
        for k, v in (("A", s.A), ("C", s.C)):
            if v is None:
                raise SpecError(
                    spec.file, f"system.{k}", f"is missing: method '{m.key}' needs the linear model"
                )
    for name in spec.tables:
        if name not in m.extra_tables:
            raise SpecError(spec.file, name, f"is not read by method '{m.key}'")
    spec.options = m.parse_options(mt, spec)
    if spec.simulate is not None:
        st = spec.simulate.table
        spec.simulate.options = m.parse_simulate(st, spec)
        st.done()
    return spec


def load_spec(path: str | Path) -> Spec:
    """Read a spec file and bind its method (see :func:`bind`)."""
    return bind(read_spec(path))


def load_spec_text(text: str, file: str = "<spec>") -> Spec:
    """Parse spec text and bind its method (see :func:`bind`)."""
    return bind(read_spec_text(text, file))


def _spec(spec: str | Path | Spec) -> Spec:
    return bind(spec) if isinstance(spec, Spec) else load_spec(spec)


def _did_you_mean(word: str, known: list[str]) -> str:
    import difflib

    m = difflib.get_close_matches(word, known, n=1)
    return f" (did you mean '{m[0]}'?)" if m else ""


def design(
    spec: str | Path | Spec, out: str | Path | None = None, progress: Progress | None = None
) -> Report:
    """Design the observer of a spec and certify every claim; write the JSON report to
    ``out`` (atomically) when given. Raises :class:`ObsdesignError` subclasses."""
    t0 = time.perf_counter()
    sp = _spec(spec)
    t1 = time.perf_counter()
    m = get_method(sp.method)
    d = m.design(sp, progress)
    t2 = time.perf_counter()
    claims = certify(sp, d.parameters)
    t3 = time.perf_counter()
    report = Report(
        method=sp.method,
        spec=sp.text,
        spec_file=sp.file,
        spec_sha256=sp.sha256,
        parameters=d.parameters,
        claims=claims,
        solver=d.solver_dict(),
        timings={
            "parse_s": round(t1 - t0, 4),
            "design_s": round(t2 - t1, 4),
            "certify_s": round(t3 - t2, 4),
        },
        notes=d.notes,
    )
    if out is not None:
        write_atomic(out, report.to_json())
    return report


def verify(report: str | Path | Report, spec: str | Path | None = None) -> Report:
    """Re-check every claim of a report from the spec and the parameters alone.

    The spec is the one embedded in the report, or ``spec`` when given; either way its
    sha256 must equal the report's ``spec_sha256``. Stored statuses are ignored: the returned
    report carries freshly computed claims.
    """
    t0 = time.perf_counter()
    if isinstance(report, Report):
        rep, problems = Report.from_dict(report.to_dict())
    else:
        rep, problems = Report.load(report)
    if spec is not None:
        p = Path(spec)
        try:
            text = p.read_bytes().decode("utf-8")
        except OSError as e:
            raise InputError(f"{p}: cannot read spec ({e.strerror})") from None
        file = str(p)
    else:
        text, file = rep.spec, rep.spec_file or "<embedded spec>"
    sha = hashlib.sha256(text.encode("utf-8")).hexdigest()
    if sha != rep.spec_sha256:
        where = f"spec {file}" if spec is not None else "the embedded spec"
        claims = [
            exact_claim(
                "spec-hash",
                "the report was made from this spec",
                "report.spec_sha256",
                "sha256",
                0,
                False,
                f"{where} has sha256 {sha[:12]}…, the report was made from {rep.spec_sha256[:12]}…",
                float_ok=False,
            )
        ]
        return _replace_claims(rep, claims, time.perf_counter() - t0)
    if rep.method not in method_keys():
        raise InputError(f"report: unknown method '{rep.method}'")
    sp = load_spec_text(text, file)
    if sp.method != rep.method:
        raise InputError(f"report: method '{rep.method}' but the spec says '{sp.method}'")
    claims: list[Claim] = []
    if problems:
        claims.append(
            exact_claim(
                "parameters-consistent",
                "every float parameter equals its exact value",
                "report.parameters",
                "comparison",
                0,
                False,
                "; ".join(problems),
                float_ok=False,
            )
        )
    claims += certify(sp, rep.parameters)
    return _replace_claims(rep, claims, time.perf_counter() - t0)


def certify(spec: Spec, params: Parameters) -> list[Claim]:
    """Every claim of the spec's method recomputed from the spec and ``params`` alone.

    The generic contract runs first: each of the method's ``required_params`` must be
    present (a failed ``<key>-present`` claim otherwise). Malformed parameters give a failed
    ``parameters-wellformed`` claim, never an exception."""
    sp = bind(spec)
    m = get_method(sp.method)
    claims: list[Claim] = []
    if not params.require(m.required_params, claims):
        return claims
    try:
        claims += m.certify(sp, params)
    except ObsdesignError:
        raise
    except (KeyError, ValueError, TypeError, IndexError, ZeroDivisionError, AttributeError) as e:
        claims.append(
            exact_claim(
                "parameters-wellformed",
                "the report's parameters have the expected form",
                "report.parameters",
                "parse",
                0,
                False,
                f"{type(e).__name__}: {e}",
                float_ok=False,
            )
        )
    return claims


def _replace_claims(rep: Report, claims: list[Claim], seconds: float) -> Report:
    rep.claims = claims
    rep.timings = {**rep.timings, "verify_s": round(seconds, 4)}
    return rep


def simulate(
    spec: str | Path | Spec,
    report: str | Path | Report | None = None,
    options: dict[str, str] | None = None,
    **kwargs: Any,
) -> SimResult:
    """Simulate the plant and the designed observer over the spec's ``[simulate]`` scenario.

    Uses the parameters of ``report`` when given (after checking its spec hash), else designs.
    ``options`` are ``--option KEY=VALUE`` texts, validated against the method's declared
    ``sim_options`` (unknown key or bad value: :class:`InputError`); ``kwargs`` are typed
    values passed as they are.
    """
    sp = _spec(spec)
    kwargs = {**get_method(sp.method).parse_sim_options(options or {}), **kwargs}
    if sp.simulate is None:
        raise InputError(f"{sp.file}: [simulate] is missing: nothing to simulate")
    if report is None:
        params: Parameters = get_method(sp.method).design(sp).parameters
    else:
        rep, problems = (
            Report.from_dict(report.to_dict())
            if isinstance(report, Report)
            else Report.load(report)
        )
        if rep.spec_sha256 != sp.sha256:
            raise InputError(f"{sp.file}: the report was made from another spec (sha256 differs)")
        if problems:
            raise InputError(f"report: {problems[0]}")
        params = rep.parameters
    return get_method(sp.method).simulate(sp, params, **kwargs)


@dataclass
class CheckRow:
    """One row of ``check``: the spec, its verdict and the key numbers."""

    spec: str
    method: str
    code: int
    certified: int
    numerical: int
    failed: int
    summary: str
    seconds: float
    message: str = ""


def spec_files(paths: list[str | Path]) -> list[Path]:
    """Expand folders to their ``*.toml`` files (sorted); keep files as given."""
    out: list[Path] = []
    for p in map(Path, paths):
        if p.is_dir():
            out += sorted(p.glob("*.toml"))
        else:
            out.append(p)
    return out


def check_one(path: Path) -> CheckRow:
    """Design, serialize, reload and verify one spec."""
    t0 = time.perf_counter()
    try:
        rep = design(path)
        ver = verify(Report.from_dict(rep.to_dict())[0])
        code = ver.exit_code()
        counts = ver.status_counts()
        msg = "; ".join(f"{c.id}: {c.detail}" for c in ver.failed)
        summary = get_method(rep.method).summary(ver.parameters)
        return CheckRow(
            str(path),
            rep.method,
            code,
            counts["certified"],
            counts["numerical"],
            counts["failed"],
            summary,
            time.perf_counter() - t0,
            msg,
        )
    except ObsdesignError as e:
        return CheckRow(
            str(path), "?", e.exit_code, 0, 0, 0, "", time.perf_counter() - t0, e.message
        )


def check(paths: list[str | Path], on_start: Any = None) -> list[CheckRow]:
    """Design and verify every spec under ``paths``; ``on_start(path)`` is called before each."""
    files = spec_files(paths)
    if not files:
        raise InputError(f"no spec files (*.toml) in {', '.join(map(str, paths))}")
    rows = []
    for f in files:
        if on_start is not None:
            on_start(f)
        rows.append(check_one(f))
    return rows


def check_exit_code(rows: list[CheckRow]) -> int:
    """0 if every row passed, else the largest exit code among the rows."""
    return max((r.code for r in rows), default=EXIT_OK)


def methods() -> list[Method]:
    """Every method this build knows, by key."""
    return [get_method(k) for k in method_keys()]


def template(key: str) -> str:
    """The commented spec template of method ``key`` (``obsdesign init``)."""
    return method(key).template()


def schema() -> dict[str, Any]:
    """The JSON schema of the spec format, every method's ``[method]`` and ``[simulate]``
    keys included."""
    from obsdesign.spec.schema import spec_schema

    ms = methods()
    sim: dict[str, Any] = {}
    for m in ms:
        sim.update(m.simulate_schema())
    return spec_schema([m.options_schema() for m in ms], sim)


def plot_design(spec: str | Path | Spec, params: Parameters, path: str | Path) -> Any:
    """The method's design plot (InputError when the method has none)."""
    sp = _spec(spec)
    m = get_method(sp.method)
    if m.plot_design is None:
        raise InputError(f"method '{sp.method}' has no design plot")
    return m.plot_design(sp, params, path)


def plot_simulation(spec: str | Path | Spec, result: SimResult, path: str | Path) -> Any:
    """The method's simulation plot, or the generic one (estimation error over time)."""
    sp = _spec(spec)
    m = get_method(sp.method)
    if m.plot_simulation is not None:
        return m.plot_simulation(sp, result, path)
    from obsdesign.simulate.plot import plot_result

    return plot_result(result, path, title=sp.title or sp.file)


__all__ = [
    "CheckRow",
    "ClaimStatus",
    "bind",
    "certify",
    "check",
    "design",
    "load_spec",
    "load_spec_text",
    "method",
    "methods",
    "plot_design",
    "plot_simulation",
    "schema",
    "simulate",
    "template",
    "verify",
]
