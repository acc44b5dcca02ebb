"""The Python API: design, verify, simulate, check. The CLI is a thin shell over these."""

from __future__ import annotations

import hashlib
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from obsdesign.certify.claim import Claim, ClaimStatus, exact_claim
from obsdesign.errors import EXIT_OK, InputError, ObsdesignError
from obsdesign.methods import get_method, method_keys
from obsdesign.methods.base import Progress
from obsdesign.params import Parameters
from obsdesign.report.model import Report, write_atomic
from obsdesign.simulate.result import SimResult
from obsdesign.spec import Spec, load_spec, load_spec_text


def _spec(spec: str | Path | Spec) -> Spec:
    return spec if isinstance(spec, Spec) else load_spec(spec)


def design(
    spec: str | Path | Spec, out: str | Path | None = None, progress: Progress | None = None
) -> Report:
    """Design the observer of a spec and certify every claim; write the JSON report to
    ``out`` (atomically) when given. Raises :class:`ObsdesignError` subclasses."""
    t0 = time.perf_counter()
    sp = _spec(spec)
    t1 = time.perf_counter()
    method = get_method(sp.method)
    d = method.design(sp, progress)
    t2 = time.perf_counter()
    claims = method.certify(sp, d.parameters)
    t3 = time.perf_counter()
    report = Report(
        method=sp.method,
        spec=sp.text,
        spec_file=sp.file,
        spec_sha256=sp.sha256,
        parameters=d.parameters,
        claims=claims,
        solver=d.solver,
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
    try:
        claims += get_method(rep.method).certify(sp, rep.parameters)
    except ObsdesignError:
        raise
    except (KeyError, ValueError, TypeError, IndexError, ZeroDivisionError) as e:
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
    return _replace_claims(rep, claims, time.perf_counter() - t0)


def _replace_claims(rep: Report, claims: list[Claim], seconds: float) -> Report:
    rep.claims = claims
    rep.timings = {**rep.timings, "verify_s": round(seconds, 4)}
    return rep


def simulate(
    spec: str | Path | Spec, report: str | Path | Report | None = None, **kwargs: Any
) -> SimResult:
    """Simulate the plant and the designed observer over the spec's ``[simulate]`` scenario.

    Uses the parameters of ``report`` when given (after checking its spec hash), else designs.
    """
    sp = _spec(spec)
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
        summary = get_method(rep.method).summary(rep.parameters)
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


def check(paths: list[str | Path]) -> list[CheckRow]:
    """Design and verify every spec under ``paths``."""
    files = spec_files(paths)
    if not files:
        raise InputError(f"no spec files (*.toml) in {', '.join(map(str, paths))}")
    return [check_one(f) for f in files]


def check_exit_code(rows: list[CheckRow]) -> int:
    """0 if every row passed, else the largest exit code among the rows."""
    return max((r.code for r in rows), default=EXIT_OK)


__all__ = ["CheckRow", "ClaimStatus", "check", "design", "simulate", "verify"]
