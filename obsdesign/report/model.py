"""The Report model and its JSON form; atomic writes."""

from __future__ import annotations

import json
import os
import platform
import tempfile
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path
from typing import Any

from obsdesign.certify.claim import Claim, ClaimStatus
from obsdesign.errors import EXIT_INCONCLUSIVE, EXIT_INFEASIBLE, EXIT_OK, InputError
from obsdesign.params import Parameters

SCHEMA_VERSION = "1.0"
TOP_KEYS = (
    "schema_version",
    "tool",
    "method",
    "spec",
    "spec_file",
    "spec_sha256",
    "parameters",
    "claims",
    "solver",
    "timings",
    "notes",
)
DEPS = ("numpy", "scipy", "cvxpy", "clarabel", "pycddlib", "python-flint", "mpmath")


def tool_info() -> dict[str, Any]:
    """Tool and dependency versions, recorded in every report."""
    versions: dict[str, str] = {}
    for d in DEPS:
        try:
            versions[d] = metadata.version(d)
        except metadata.PackageNotFoundError:
            versions[d] = "not installed"
    try:
        own = metadata.version("obsdesign")
    except metadata.PackageNotFoundError:
        own = "unknown"
    return {
        "name": "obsdesign",
        "version": own,
        "python": platform.python_version(),
        "dependencies": versions,
    }


@dataclass
class Report:
    """A design (or verification) report."""

    method: str
    spec: str
    spec_file: str
    spec_sha256: str
    parameters: Parameters
    claims: list[Claim]
    solver: dict[str, Any] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    tool: dict[str, Any] = field(default_factory=tool_info)
    schema_version: str = SCHEMA_VERSION

    # -- verdict ----------------------------------------------------------------------------
    @property
    def failed(self) -> list[Claim]:
        return [c for c in self.claims if c.status == ClaimStatus.FAILED]

    def exit_code(self) -> int:
        """0 when every claim holds; 4 when every failed claim still holds in floats
        (inconclusive); 1 otherwise."""
        bad = self.failed
        if not bad:
            return EXIT_OK
        if all(c.float_ok for c in bad):
            return EXIT_INCONCLUSIVE
        return EXIT_INFEASIBLE

    def status_counts(self) -> dict[str, int]:
        out = {s.value: 0 for s in ClaimStatus}
        for c in self.claims:
            out[c.status.value] += 1
        return out

    # -- JSON -------------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        return {
            "schema_version": self.schema_version,
            "tool": self.tool,
            "method": self.method,
            "spec": self.spec,
            "spec_file": self.spec_file,
            "spec_sha256": self.spec_sha256,
            "parameters": self.parameters.to_json(),
            "claims": [c.to_dict() for c in self.claims],
            "solver": self.solver,
            "timings": self.timings,
            "notes": self.notes,
        }

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=2, ensure_ascii=False)

    @classmethod
    def load(cls, path: str | Path) -> tuple[Report, list[str]]:
        """Read a report; returns it and the list of float/exact inconsistencies found."""
        p = Path(path)
        try:
            d = json.loads(p.read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise InputError(f"{p}: no such report file") from None
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
            raise InputError(f"{p}: not a readable JSON report ({e})") from None
        return cls.from_dict(d, str(p))

    @classmethod
    def from_dict(cls, d: Any, file: str = "<report>") -> tuple[Report, list[str]]:
        if not isinstance(d, dict):
            raise InputError(f"{file}: a report is a JSON object")
        for k in ("schema_version", "method", "spec", "spec_sha256", "parameters", "claims"):
            if k not in d:
                raise InputError(f"{file}: key '{k}' is missing (not an obsdesign report?)")
        if str(d["schema_version"]).split(".")[0] != SCHEMA_VERSION.split(".")[0]:
            raise InputError(
                f"{file}: schema_version {d['schema_version']} is not supported (expected {SCHEMA_VERSION})"
            )
        if not isinstance(d["spec"], str) or not isinstance(d["spec_sha256"], str):
            raise InputError(f"{file}: 'spec' must be the spec text and 'spec_sha256' its hash")
        params, problems = Parameters.from_json(d["parameters"])
        try:
            claims = [Claim.from_dict(c) for c in d["claims"]]
        except (KeyError, TypeError, ValueError) as e:
            raise InputError(f"{file}: malformed claims ({e})") from None
        return (
            cls(
                method=str(d["method"]),
                spec=d["spec"],
                spec_file=str(d.get("spec_file", "")),
                spec_sha256=d["spec_sha256"],
                parameters=params,
                claims=claims,
                solver=dict(d.get("solver", {})),
                timings=dict(d.get("timings", {})),
                notes=list(d.get("notes", [])),
                tool=dict(d.get("tool", {})),
                schema_version=str(d["schema_version"]),
            ),
            problems,
        )


def write_atomic(path: str | Path, text: str) -> Path:
    """Write text to ``path`` through a temp file in the same folder and an atomic rename, so
    that a reader never sees a half-written file and a failure leaves no file behind."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=p.parent, prefix=f".{p.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            if not text.endswith("\n"):
                f.write("\n")
        os.replace(tmp, p)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return p
